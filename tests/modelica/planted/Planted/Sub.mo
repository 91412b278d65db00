within Planted;
model Sub "Chooses Outer for C"
  extends Planted.Base(redeclare model C = Planted.Outer);
end Sub;
