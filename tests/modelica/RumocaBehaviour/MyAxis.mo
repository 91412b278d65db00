within RumocaBehaviour;
model MyAxis "A user axis: a first-order lag connected to ps.pos"
  extends Axis;
  RealOutput y "Position";
  Real x(start=0, fixed=true) "State";
equation
  der(x) = (1 - x)/0.2;
  y = x;
  connect(y, ps.pos);
end MyAxis;
