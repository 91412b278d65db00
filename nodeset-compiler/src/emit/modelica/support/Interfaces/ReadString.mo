within OpcUaSupport.Interfaces;
partial block ReadString "Reads a String value from a variable of an OPC UA server"
  outer parameter Connection connection "The connection to the OPC UA server, declared inner at the top of the model";
  parameter String nodeId = "" "NodeId of the variable: nsu=<namespace URI>;i=<number>, or i=<number> in the base namespace";
  parameter String browsePath = "" "BrowseNames from the ObjectsFolder, separated by '/', to find the variable on a server whose NodeIds differ";
  parameter String initValue = "" "The OPC UA value until the first read";
  OpcUaSupport.StringOutput y "The value read"
    annotation (Placement(transformation(extent={{100,-10},{120,10}})));
protected
  String value "The OPC UA value read: an implementation gives its equation";
equation
  y = value;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>The interface an OPC UA library implements to read a String variable: extend this block and give an equation for <code>value</code>, the value of the variable <code>nodeId</code> on the server of the <code>outer</code> <code>connection</code>. The generated <code>Instances.Bindings</code> models use it; <code>OpcUaSupport.Loopback</code> implements it with a table.</p></html>"));
end ReadString;
