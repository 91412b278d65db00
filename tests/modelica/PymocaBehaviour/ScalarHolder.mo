within PymocaBehaviour;
model ScalarHolder "An item of a replaceable class whose declaration repeats the choice of S"
  replaceable model I = Item "Class of the item";
  I item(redeclare model S = Empty) "The item";
end ScalarHolder;
