within Planted;
model Holder "Holds an M and repeats the choice of C of its default class"
  replaceable model M = Planted.Base;
  M m(redeclare model C = Planted.Empty);
end Holder;
