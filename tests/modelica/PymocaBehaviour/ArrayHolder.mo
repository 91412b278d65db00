within PymocaBehaviour;
model ArrayHolder "The same with an array of items, sized by a parameter"
  parameter Integer n = 1 "How many items";
  replaceable model I = Item "Class of the items";
  I items[n](redeclare model S = Empty) "The items";
end ArrayHolder;
