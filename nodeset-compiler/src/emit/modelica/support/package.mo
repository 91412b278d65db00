within;
package OpcUaSupport "Connectors and configuration records shared by the Modelica packages generated from OPC UA information models"
  package UsersGuide "User's Guide: the Modelica packages nodeset-compiler generates from OPC UA information models"
    annotation (
      DocumentationClass=true,
      {INFO_ICON},
      Documentation(info="<html>
<h4>What is generated</h4>
<p>nodeset-compiler reads OPC UA NodeSet2 files and writes one Modelica package per namespace, next to this
support package. Neither depends on the Modelica Standard Library. A namespace package holds:</p>
<ul>
<li><code>Types</code>: one class per DataType: an <code>enumeration</code>, a <code>record</code> for a
structure (it extends the record of its supertype), or a <code>type</code> for a simple DataType.
<code>EnumerationValues</code> gives the OPC UA value of each literal, since Modelica numbers literals from 1.</li>
<li><code>ObjectTypes</code>: one model per ObjectType, extending the model of its supertype; a
<code>partial model</code> where the ObjectType is abstract; a <code>record</code> of its fields for an event
type.</li>
<li><code>Declarations</code>: the classes of instance declarations that add children to their type, named
<code>Owner_BrowsePath</code> (<code>AxisType_ParameterSet</code>).</li>
<li><code>Instances</code>: one model per instance of the namespace below the ObjectsFolder, and
<code>Objects</code>, which holds them all and the <code>Nodes</code> record of their variables.</li>
</ul>
<p>Every class says what it stands for: its description string starts with the BrowseName, its
<code>Documentation</code> holds the Description of the nodeset, and its <code>__OPCUA</code> annotation holds
the NodeId and BrowseName.</p>

<h4>Members</h4>
<ul>
<li>A property is a <code>parameter</code>. A data variable is a connector of this package. A value the
model publishes (clients may only read it) is an input, <code>RealInput</code>, that nothing binds: the physics
that computes it connects to it. A value clients may write (AccessLevel CurrentWrite) is an output,
<code>RealOutput</code>, bound to the value in the nodeset (else zero, false or an empty string), which the model
hands on to the physics.</li>
<li>A class whose components hold such inputs is partial. Its complete variant, <code>Complete.X</code>,
binds every one of them to the nodeset's value and simulates as it is; instances are complete too.</li>
<li>An object is a component whose class is a replaceable alias: <code>replaceable model Axes =
...Declarations.MotionDeviceType_Axes; Axes axes;</code>. Redeclare the alias to use a model of your own. Where
the class is partial, the alias defaults to its complete variant and is constrained by the class
(<code>replaceable model AxisIdentifier = OpcUaRobotics.Complete.AxisType constrainedby
OpcUaRobotics.ObjectTypes.AxisType</code>).</li>
<li>An optional member exists when <code>use_x = true</code>: <code>parameter Boolean use_x = false</code>,
<code>X x if use_x</code>.</li>
<li>A placeholder <code>&lt;X&gt;</code> is an array: <code>parameter Integer nX</code> (at least one, and one by
default, where the placeholder is mandatory), <code>parameter String xBrowseNames[nX]</code> (the elements'
BrowseNames, <code>\"&lt;X&gt;\"</code> until you name them), <code>replaceable model X</code>, <code>X x[nX]</code>.
Where named components fill a mandatory placeholder (in an instance, or a type that names them), its array is
empty: <code>nX(min=0)=0</code>.</li>
<li>A member held by a non-hierarchical reference (Requires, Moves, HasSlave, ...) lives elsewhere: it is
<code>parameter String x</code>, the NodeId of its target.</li>
<li>Methods are comments: call them through an OPC UA client. The methods of a state machine (Start, Suspend,
Resume, Halt, Reset of a program or skill) are Boolean trigger inputs: a rising edge stands for a call.</li>
</ul>

<h4>Using a generated model</h4>
<p>Extend a type and connect what your model computes to the inputs it publishes (optional members such as
ActualSpeed once switched on):</p>
<pre>model DrivenAxis
  extends OpcUaRobotics.ObjectTypes.AxisType(parameterSet(use_actualSpeed=true));
  FirstOrder drive(T=0.2, u=1);
equation
  connect(drive.y, parameterSet.actualPosition);
  connect(drive.dy, parameterSet.actualSpeed);
end DrivenAxis;</pre>
<p>and fill placeholders by redeclaring their class and setting their count:</p>
<pre>extends OpcUaRobotics.Declarations.MotionDeviceType_Axes(
  nAxisIdentifier=2, axisIdentifierBrowseNames={\"Axis1\", \"Axis2\"},
  redeclare model AxisIdentifier = DrivenAxis);</pre>
<p>Where nothing computes a published value, use the complete variant (<code>OpcUaRobotics.Complete.AxisType</code>),
or bind the value with a modifier.</p>

<h4>Binding to OPC UA</h4>
<p><code>Instances.Bindings</code> holds each instance again, extended by one block per variable: a variable
clients may write is read from the server (<code>OpcUaSupport.Interfaces.ReadReal</code>, ...), a variable the
model publishes is written to it. Each block has the instance's NodeId, browse path and the conversion from the
engineering unit to SI. The block classes are replaceable and default to <code>OpcUaSupport.Loopback</code>,
which reads tables and needs no server. Extend the interfaces with an OPC UA library (the DLR OPC UA library,
or another) and redeclare them, with one <code>inner parameter OpcUaSupport.Interfaces.Connection
connection</code> at the top of the model:</p>
<pre>model Cell
  inner parameter OpcUaSupport.Interfaces.Connection connection(endpointUrl=\"opc.tcp://cell:4840\");
  NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell cell(
    redeclare block ReadReal = MyOpcUa.ReadReal);
end Cell;</pre>
<p><code>OpcUaSupport.Live</code> implements the blocks over OPC UA itself, with the shared library
<code>nodeset_live</code> (built from the <code>nodeset-live</code> crate, placed in
<code>OpcUaSupport/Resources/Library/&lt;platform&gt;</code>): <code>Live.Server</code> when the simulation is the
server (component simulation: it serves the namespaces of the nodesets), <code>Live.Client</code> when it is a
client of a real server. Declare its <code>inner</code> endpoint beside the connection and redeclare the block
classes with <code>Live.Server.ReadReal</code>, ... (see <code>OpcUaSupport.Live</code>).</p>
<p><code>Examples</code> holds each instance ready to simulate (its binding model with the loopback blocks,
beside the <code>inner</code> connection), with an <code>experiment</code> annotation.
<code>Instances.Objects.nodes</code> is the <code>Nodes</code> configuration record of the DLR library's
server and client blocks: every variable of the instances it can create.</p>

<h4>State machines</h4>
<p>A state machine has <code>currentStateNumber</code>, an Integer holding the StateNumber of the nodeset, one
constant per state, and <code>currentStateText</code>, the DisplayName of the current state, which
<code>currentState</code> shows. It starts in the initial state of the nodeset (Ready for programs and skills)
and moves along the transitions of the nodeset when a trigger rises.</p>

<h4>Units</h4>
<p>A variable with EngineeringUnits holds its SI value, as the Modelica Standard Library does:
<code>unit=\"m\", displayUnit=\"mm\", quantity=\"Length\"</code>, and a value from the nodeset is converted. Its
<code>__OPCUA</code> annotation keeps the UNECE code and the conversion from the OPC UA value:
<code>engineeringUnit=\"MMT\", siFactor=0.001</code>, and <code>siOffset=273.15</code> for degree Celsius. So
SI value = siFactor * OPC UA value + siOffset. A unit nodeset-compiler cannot map (percent, for one) gets no
<code>unit</code>; the description string says which it was.</p>

<h4>The __OPCUA annotation</h4>
<p>Each member names its node: <code>browsePath</code> (from the object its class stands for),
<code>nodeId</code> (in the form <code>nsu=URI;i=5</code>), <code>dataType</code>, <code>typeDefinition</code>
for objects, <code>referenceType</code> for a non-hierarchical member, and the unit conversion above. In a type,
the NodeId is the one of the declaration; an instance's own NodeIds are in the <code>Nodes</code> record of
<code>Instances.Objects</code>.</p>

<h4>Connecting to a server</h4>
<p><code>Nodes</code> and <code>VariableNode</code> follow the configuration record of the DLR OPC UA library
(Sch&ouml;nfeld et al., Modelica Conference 2021): each instance variable with its NodeId, built-in type and
initial value, in OPC UA units, and its browse path, for a server whose NodeIds differ.</p>

<h4>Checked by</h4>
<p>Every generated class is checked with two independent Modelica front ends, rumoca and pymoca, and by
structural checks of nodeset-compiler's own (no class contains itself, no conditional component read in an
equation, no modifier naming a member that does not exist). Hand-written example models built on the
generated classes are simulated.</p>
</html>"));
  end UsersGuide;
  annotation (
    version="{VERSION}",
    {PACKAGE_ICON},
    Documentation(info="<html>
<p>This package is emitted by nodeset-compiler next to the packages it generates from OPC UA NodeSet2 files. It
does not depend on the Modelica Standard Library.</p>
<p>Start with the <code>UsersGuide</code>: how the generated packages stand for an information model, and how
to use them.</p>
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
