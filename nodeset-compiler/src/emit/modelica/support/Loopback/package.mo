within OpcUaSupport;
package Loopback "The read and write blocks without a server: tables in, written values out"
  annotation ({PACKAGE_ICON}, Documentation(info="<html><p>An implementation of
<code>OpcUaSupport.Interfaces</code> in Modelica alone. A Real read follows a table of times and values; the
other reads give the value the nodeset holds; a write shows the value it would send as its output
<code>written</code>. The generated <code>Instances.Bindings</code> models use these blocks until they are
redeclared, so a bound instance simulates as it is, and tests check a binding without a server.</p></html>"));
end Loopback;
