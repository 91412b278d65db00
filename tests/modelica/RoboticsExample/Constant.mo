within RoboticsExample;
block Constant "Output y is the constant k"
  parameter Real k = 0 "Value of the output";
  OpcUaSupport.RealOutput y "Output"
    annotation (Placement(transformation(extent={{100,-10},{120,10}})));
equation
  y = k;
  annotation (
    Documentation(info="<html><p><code>y = k</code>.</p></html>"),
    Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={0,0,127}, fillColor={255,255,255},
      fillPattern=FillPattern.Solid), Text(extent={{-90,40},{90,-40}}, textString="%k")}));
end Constant;
