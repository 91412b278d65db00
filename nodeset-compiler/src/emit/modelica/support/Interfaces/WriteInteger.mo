within OpcUaSupport.Interfaces;
partial block WriteInteger "Writes an Integer value to a variable of an OPC UA server"
  outer parameter Connection connection "The connection to the OPC UA server, declared inner at the top of the model";
  parameter String nodeId = "" "NodeId of the variable: nsu=<namespace URI>;i=<number>, or i=<number> in the base namespace";
  parameter String browsePath = "" "BrowseNames from the ObjectsFolder, separated by '/', to find the variable on a server whose NodeIds differ";
  OpcUaSupport.IntegerInput u "The value to write"
    annotation (Placement(transformation(extent={{-120,-10},{-100,10}})));
  Integer value = u "The OPC UA value an implementation writes";
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>The interface an OPC UA library implements to write a Integer variable: extend this block and send <code>value</code> to the variable <code>nodeId</code> on the server of the <code>outer</code> <code>connection</code>, at the connection's sample period or when it changes.</p></html>"));
end WriteInteger;
