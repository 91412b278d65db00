within PymocaBehaviour;
model Item "Declares the replaceable class S and a component of it"
  replaceable model S = Empty "Class of s";
  S s "Component of the replaceable class";
end Item;
