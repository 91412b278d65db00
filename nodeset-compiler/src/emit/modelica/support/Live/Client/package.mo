within OpcUaSupport.Live;
package Client "The blocks of a simulation that is a client of an OPC UA server (interactive simulation and control)"
  annotation ({PACKAGE_ICON}, Documentation(info="<html><p>Declare <code>inner OpcUaSupport.Live.Client.Endpoint opcuaClient</code>
beside <code>inner parameter OpcUaSupport.Interfaces.Connection connection</code> (its <code>samplePeriod</code>
is the blocks'), and redeclare the block classes of a generated <code>Bindings</code> model with these.</p></html>"));
end Client;
