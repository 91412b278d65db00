within RumocaBehaviour;
model PinnedRobot "Like Robot, with the axis repeating its own choice of PS"
  extends Base(redeclare model PS = OuterPS);
  MyAxis a(redeclare model PS = InnerPS) "The axis";
end PinnedRobot;
