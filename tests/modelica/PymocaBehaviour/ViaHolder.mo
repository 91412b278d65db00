within PymocaBehaviour;
model ViaHolder "An array of items whose declaration repeats the choice through an alias of this class (what the generator writes)"
  parameter Integer n = 1 "How many items";
  replaceable model I = Item "Class of the items";
  replaceable model I_S = Empty "Class of S in I";
  I items[n](redeclare model S = I_S) "The items";
end ViaHolder;
