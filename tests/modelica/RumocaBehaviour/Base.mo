within RumocaBehaviour;
model Base "Declares the replaceable class PS and a component of it"
  replaceable model PS = Empty "Class of ps";
  PS ps "Component of the replaceable class";
end Base;
