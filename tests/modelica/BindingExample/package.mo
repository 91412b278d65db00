within;
package BindingExample "The drilling cell bound to OPC UA: through the loopback blocks, and live"
  annotation (
    version="1.0.0",
    uses(NodesetCompilerDrillingProcess(version="1.0.0"), OpcUaSupport(version="0.1.0")),
    Documentation(info="<html><p>A hand-written user model, not generated: the generated binding model of the
drilling cell, <code>NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell</code>, with its reads fed
by tables (<code>OpcUaSupport.Loopback</code>) instead of a server. The test <code>tests/tests/modelica.rs</code>
simulates it and checks that each value arrives in SI units where the instance uses it, and that the write
blocks send the values the instance publishes, in OPC UA units.</p></html>"),
    Icon(graphics={Rectangle(extent={{-100,100},{100,-100}}, lineColor={128,128,128}, fillColor={240,240,240}, fillPattern=FillPattern.Solid, radius=25)}));
end BindingExample;
