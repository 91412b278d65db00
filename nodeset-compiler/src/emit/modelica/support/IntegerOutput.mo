within OpcUaSupport;
connector IntegerOutput = output Integer "'output Integer' as connector"
  annotation (
    defaultComponentName="y",
    Icon(coordinateSystem(preserveAspectRatio=true, extent={{-100,-100},{100,100}}),
      graphics={Polygon(lineColor={255,127,0}, fillColor={255,255,255}, fillPattern=FillPattern.Solid, points={{-100,100},{100,0},{-100,-100},{-100,100}})}),
    Documentation(info="<html><p>Connector with one output signal of type Integer, shaped like the connectors of
Modelica.Blocks.Interfaces so that blocks of both libraries connect.</p></html>"));
