within OpcUaSupport;
connector IntegerInput = input Integer "'input Integer' as connector"
  annotation (
    defaultComponentName="u",
    Icon(coordinateSystem(preserveAspectRatio=true, extent={{-100,-100},{100,100}}),
      graphics={Polygon(lineColor={255,127,0}, fillColor={255,127,0}, fillPattern=FillPattern.Solid, points={{-100,100},{100,0},{-100,-100},{-100,100}})}),
    Documentation(info="<html><p>Connector with one input signal of type Integer, shaped like the connectors of
Modelica.Blocks.Interfaces so that blocks of both libraries connect.</p></html>"));
