within OpcUaSupport;
connector BooleanInput = input Boolean "'input Boolean' as connector"
  annotation (
    defaultComponentName="u",
    Icon(coordinateSystem(preserveAspectRatio=true, extent={{-100,-100},{100,100}}),
      graphics={Polygon(lineColor={255,0,255}, fillColor={255,0,255}, fillPattern=FillPattern.Solid, points={{-100,100},{100,0},{-100,-100},{-100,100}})}),
    Documentation(info="<html><p>Connector with one input signal of type Boolean, shaped like the connectors of
Modelica.Blocks.Interfaces so that blocks of both libraries connect.</p></html>"));
