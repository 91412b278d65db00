within OpcUaSupport.Live.Client;
block ReadBoolean "Reads a Boolean variable: from the server"
  extends OpcUaSupport.Interfaces.ReadBoolean;
  outer OpcUaSupport.Live.Client.Endpoint opcuaClient "The client, declared inner at the top of the model";
  parameter Boolean stopOnError = false "End the simulation when a read fails (else a warning and the status output)";
  final parameter String node = if opcuaClient.useBrowsePaths and browsePath <> "" then browsePath else nodeId "What the calls name: nodeId, or browsePath where the endpoint says so";
  OpcUaSupport.IntegerOutput status(start = 0, fixed = true) "0: Good; else the OPC UA status code of the last read (negative for Bad)"
    annotation (Placement(transformation(extent={{100,-50},{120,-30}})));
protected
  discrete Boolean held(start = initValue, fixed = true) "The value of the last sample";
algorithm
  when sample(0, connection.samplePeriod) then
    (held, status) := OpcUaSupport.Live.Functions.clientReadBoolean(opcuaClient.client, node, pre(held));
    if status <> 0 and status <> pre(status) then
      OpcUaSupport.Live.Functions.report(stopOnError, "reading " + node, OpcUaSupport.Live.Functions.clientError(opcuaClient.client));
    end if;
  end when;
equation
  value = held;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>Reads the variable <code>nodeId</code> every
<code>connection.samplePeriod</code> and holds it between samples. A failed read keeps the last value and sets
<code>status</code>.</p></html>"));
end ReadBoolean;
