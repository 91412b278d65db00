within Planted;
model ExtendsModifierTypo "Names inn.vv in its extends clause"
  extends Planted.Outer(inn(vv=1));
end ExtendsModifierTypo;
