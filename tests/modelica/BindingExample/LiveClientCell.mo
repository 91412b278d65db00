within BindingExample;
model LiveClientCell "The bound drilling cell as a client of the real cell's server (interactive simulation and control)"
  extends NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell(
    redeclare block ReadReal = OpcUaSupport.Live.Client.ReadReal,
    redeclare block WriteInteger = OpcUaSupport.Live.Client.WriteInteger);
  inner parameter OpcUaSupport.Interfaces.Connection connection(endpointUrl="opc.tcp://cell:4840/", samplePeriod=0.1)
    "The real cell's server and the sample period";
  inner OpcUaSupport.Live.Client.Endpoint opcuaClient(
    url=connection.endpointUrl,
    pkiDir="pki/simulation-client",
    user="operator",
    passwordEnv="CELL_PASSWORD",
    useBrowsePaths=true) "The session to the real cell, secure by default; the password is read from $CELL_PASSWORD; variables found by browse path";
  annotation (
    experiment(StopTime=10, Interval=0.1),
    Documentation(info="<html><p>The generated binding model of the drilling cell extended with its Real reads and Integer
writes redeclared to <code>OpcUaSupport.Live.Client</code>. The blocks find their variables by browse path (the real cell's NodeIds may differ from the nodeset's). A server that is away gives each block's <code>status</code> output its
status and a warning, the value read last is held, and the client connects again by itself. Checked here by rumoca and pymoca, not run.</p></html>"));
end LiveClientCell;
