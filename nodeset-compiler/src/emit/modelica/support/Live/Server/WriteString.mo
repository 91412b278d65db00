within OpcUaSupport.Live.Server;
block WriteString "Writes a String variable: published to clients"
  extends OpcUaSupport.Interfaces.WriteString;
  outer OpcUaSupport.Live.Server.Endpoint opcuaServer "The server, declared inner at the top of the model";
  parameter Boolean stopOnError = false "End the simulation when a write fails (else a warning and the status output)";
  OpcUaSupport.IntegerOutput status(start = 0, fixed = true) "0: Good; else the OPC UA status code of the last write (negative for Bad)"
    annotation (Placement(transformation(extent={{100,-50},{120,-30}})));
algorithm
  when sample(0, connection.samplePeriod) then
    status := OpcUaSupport.Live.Functions.serverWriteString(opcuaServer.server, nodeId, value);
    if status <> 0 and status <> pre(status) then
      OpcUaSupport.Live.Functions.report(stopOnError, "writing " + nodeId, OpcUaSupport.Live.Functions.serverError(opcuaServer.server));
    end if;
  end when;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>Writes <code>value</code> to the variable
<code>nodeId</code> every <code>connection.samplePeriod</code>. A failed write sets <code>status</code>.</p></html>"));
end WriteString;
