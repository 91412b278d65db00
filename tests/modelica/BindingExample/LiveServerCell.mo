within BindingExample;
model LiveServerCell "The bound drilling cell served live: the simulation is the OPC UA server (component simulation)"
  extends NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell(
    redeclare block ReadReal = OpcUaSupport.Live.Server.ReadReal,
    redeclare block WriteInteger = OpcUaSupport.Live.Server.WriteInteger,
    redeclare block WriteString = OpcUaSupport.Live.Server.WriteString);
  inner parameter OpcUaSupport.Interfaces.Connection connection(samplePeriod=0.05)
    "The sample period of the blocks";
  inner OpcUaSupport.Live.Server.Endpoint opcuaServer(
    port=4840,
    nodesets="nodesets/DrillingProcess.NodeSet2.xml;nodesets/CommonSkills.NodeSet2.xml;nodesets/RobotCell.NodeSet2.xml;nodesets/vendor",
    pkiDir="pki/drilling-cell",
    usersFile="users.txt") "The server of the drilling cell's namespaces";
  annotation (
    experiment(StopTime=10, Interval=0.05),
    Documentation(info="<html><p>The generated binding model of the drilling cell extended with its Real reads and its Integer and
String writes redeclared to <code>OpcUaSupport.Live.Server</code>: the simulation serves the cell's namespaces, clients
(an HMI, a PLC under test) write ApproachDistance and Depth and read the Result and the skills' CurrentState. Runs where the <code>nodeset_live</code> library is in
<code>OpcUaSupport/Resources/Library/&lt;platform&gt;</code>; checked here by rumoca and pymoca, not run. (The redeclarations are in the <code>extends</code> clause: pymoca 0.12 cannot flatten a redeclaration of these block classes in a component modification, <code>cell(redeclare block ReadReal = ...)</code>, not even to the loopback blocks.) (no
Modelica tool on these machines runs external C functions).</p></html>"));
end LiveServerCell;
