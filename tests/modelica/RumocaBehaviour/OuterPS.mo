within RumocaBehaviour;
model OuterPS "The class the robot chooses: one constant"
  extends Empty;
  Real speed = 1 "Speed";
end OuterPS;
