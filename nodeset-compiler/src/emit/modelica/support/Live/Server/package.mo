within OpcUaSupport.Live;
package Server "The blocks of a simulation that runs an OPC UA server (component simulation)"
  annotation ({PACKAGE_ICON}, Documentation(info="<html><p>Declare <code>inner OpcUaSupport.Live.Server.Endpoint opcuaServer</code>
beside <code>inner parameter OpcUaSupport.Interfaces.Connection connection</code> (its <code>samplePeriod</code>
is the blocks'), and redeclare the block classes of a generated <code>Bindings</code> model with these.</p></html>"));
end Server;
