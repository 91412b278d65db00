within RumocaBehaviour;
model CMid "One extends level between the declaration and the redeclaration"
  extends CBase;
end CMid;
