within OpcUaSupport.Live.Client;
block WriteBoolean "Writes a Boolean variable: to the server"
  extends OpcUaSupport.Interfaces.WriteBoolean;
  outer OpcUaSupport.Live.Client.Endpoint opcuaClient "The client, declared inner at the top of the model";
  parameter Boolean stopOnError = false "End the simulation when a write fails (else a warning and the status output)";
  final parameter String node = if opcuaClient.useBrowsePaths and browsePath <> "" then browsePath else nodeId "What the calls name: nodeId, or browsePath where the endpoint says so";
  OpcUaSupport.IntegerOutput status(start = 0, fixed = true) "0: Good; else the OPC UA status code of the last write (negative for Bad)"
    annotation (Placement(transformation(extent={{100,-50},{120,-30}})));
algorithm
  when sample(0, connection.samplePeriod) then
    status := OpcUaSupport.Live.Functions.clientWriteBoolean(opcuaClient.client, node, value);
    if status <> 0 and status <> pre(status) then
      OpcUaSupport.Live.Functions.report(stopOnError, "writing " + node, OpcUaSupport.Live.Functions.clientError(opcuaClient.client));
    end if;
  end when;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>Writes <code>value</code> to the variable
<code>nodeId</code> every <code>connection.samplePeriod</code>. A failed write sets <code>status</code>.</p></html>"));
end WriteBoolean;
