within RumocaBehaviour;
model DeepRobot "Chooses OuterPS; its axis is one level further in"
  extends Base(redeclare model PS = OuterPS);
  Mid m "A folder";
end DeepRobot;
