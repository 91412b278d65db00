within RumocaBehaviour;
model ArrayRobot "Like Robot, with an array of axes"
  extends Base(redeclare model PS = OuterPS);
  MyAxis a[1] "The axes";
end ArrayRobot;
