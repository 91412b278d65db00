within OpcUaSupport.Interfaces;
record Connection "The OPC UA server the read and write blocks of a model talk to"
  String endpointUrl = "opc.tcp://localhost:4840" "Endpoint URL of the server";
  Real samplePeriod(unit="s") = 0.1 "How often values are read and written";
  annotation ({RECORD_ICON}, Documentation(info="<html><p>Declare one at the top of a model that holds bound
instances, <code>inner parameter OpcUaSupport.Interfaces.Connection connection(endpointUrl=\"opc.tcp://robot:4840\")</code>;
every read and write block finds it as its <code>outer</code> <code>connection</code>. An OPC UA library that
implements the blocks reads its endpoint and sample period here (or declares its own <code>inner</code> client
or server block beside it). Namespaces are named by URI in each block's <code>nodeId</code>, so the namespace
indices of the server do not matter.</p></html>"));
end Connection;
