within Planted;
model NestedModifierTypo "Names inn.vv, which Inner lacks"
  Planted.Outer o(inn(vv=1));
end NestedModifierTypo;
