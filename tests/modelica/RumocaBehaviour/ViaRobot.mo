within RumocaBehaviour;
model ViaRobot "The axes' pin names an alias of the robot"
  extends Base(redeclare model PS = OuterPS);
  replaceable model A = MyAxis "Class of the axes";
  replaceable model A_PS = InnerPS "Class of PS in the axes";
  A a[1](redeclare model PS = A_PS) "The axes";
end ViaRobot;
