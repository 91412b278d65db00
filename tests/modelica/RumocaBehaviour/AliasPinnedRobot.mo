within RumocaBehaviour;
model AliasPinnedRobot "Like Robot, the axis class a replaceable alias that repeats the axis's choice"
  extends Base(redeclare model PS = OuterPS);
  replaceable model A = MyAxis(redeclare model PS = InnerPS) "Class of the axes";
  A a[1] "The axes";
end AliasPinnedRobot;
