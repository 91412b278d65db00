within Planted;
model ModifierTypo "Names vv, which Inner lacks"
  Planted.Inner i(vv=1);
end ModifierTypo;
