within RumocaBehaviour;
model CAxis "Redeclares the component two extends levels below its declaration"
  extends CMid(redeclare InnerPS ps);
  RealOutput y "Position";
  Real x(start=0, fixed=true) "State";
equation
  der(x) = (1 - x)/0.2;
  y = x;
  connect(y, ps.pos);
end CAxis;
