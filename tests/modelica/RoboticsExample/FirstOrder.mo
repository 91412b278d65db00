within RoboticsExample;
block FirstOrder "Output y follows input u with a first-order lag, and gives its rate of change"
  parameter Real T(unit="s") = 0.2 "Time constant";
  parameter Real y_start = 0 "Output at the start";
  OpcUaSupport.RealInput u "Target"
    annotation (Placement(transformation(extent={{-140,-20},{-100,20}})));
  OpcUaSupport.RealOutput y(start=y_start, fixed=true) "Output"
    annotation (Placement(transformation(extent={{100,30},{120,50}})));
  OpcUaSupport.RealOutput dy "Rate of change of the output"
    annotation (Placement(transformation(extent={{100,-50},{120,-30}})));
equation
  der(y) = (u - y)/T;
  dy = der(y);
  annotation (
    Documentation(info="<html><p><code>T*der(y) = u - y</code>, starting at <code>y_start</code>.</p></html>"),
    Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={0,0,127}, fillColor={255,255,255},
      fillPattern=FillPattern.Solid), Text(extent={{-90,40},{90,-40}}, textString="T=%T")}));
end FirstOrder;
