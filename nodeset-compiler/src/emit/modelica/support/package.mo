within;
package OpcUaSupport "Connectors and configuration records shared by the Modelica packages generated from OPC UA information models"
  annotation (
    version="{VERSION}",
    Documentation(info="<html>
<p>This package is emitted by nodeset-compiler next to the packages it generates from OPC UA NodeSet2 files. It
does not depend on the Modelica Standard Library.</p>
<ul>
<li><code>RealInput</code> ... <code>StringOutput</code>: signal connectors shaped like those of
<code>Modelica.Blocks.Interfaces</code>. Generated models declare read-only OPC UA variables as outputs and
writable ones as inputs.</li>
<li><code>NodeId</code>, <code>BrowsePath</code>: how a node is addressed; every generated variable carries the
same information in its <code>__OPCUA(browsePath, nodeId, dataType)</code> annotation.</li>
<li><code>VariableNode</code>, <code>Nodes</code>: the configuration record of the DLR OPC UA library
(Sch&ouml;nfeld et al., Modelica Conference 2021), filled by the generated <code>Instances.Objects</code> models.
Unlike the original, <code>Nodes.vars</code> is sized by <code>Nodes.nVars</code>, because an unsized array of
records inside a record is not accepted by every Modelica tool.</li>
</ul>
</html>"));
end OpcUaSupport;
