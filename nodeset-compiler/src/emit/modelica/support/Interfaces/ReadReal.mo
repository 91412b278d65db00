within OpcUaSupport.Interfaces;
partial block ReadReal "Reads a Real value from a variable of an OPC UA server"
  outer parameter Connection connection "The connection to the OPC UA server, declared inner at the top of the model";
  parameter String nodeId = "" "NodeId of the variable: nsu=<namespace URI>;i=<number>, or i=<number> in the base namespace";
  parameter String browsePath = "" "BrowseNames from the ObjectsFolder, separated by '/', to find the variable on a server whose NodeIds differ";
  parameter Real initValue = 0 "The OPC UA value until the first read";
  parameter Real siFactor = 1 "y = siFactor*value + siOffset: from the engineering unit of the variable to SI";
  parameter Real siOffset = 0 "y = siFactor*value + siOffset: from the engineering unit of the variable to SI";
  OpcUaSupport.RealOutput y "The value read, in SI units"
    annotation (Placement(transformation(extent={{100,-10},{120,10}})));
protected
  Real value "The OPC UA value read: an implementation gives its equation";
equation
  y = siFactor*value + siOffset;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>The interface an OPC UA library implements to read a Real variable: extend this block and give an equation for <code>value</code>, the value of the variable <code>nodeId</code> on the server of the <code>outer</code> <code>connection</code>. <code>value</code> is in the engineering unit of the variable; <code>y</code> is its SI value, <code>siFactor*value + siOffset</code>, as the <code>__OPCUA</code> annotation of the generated component gives them. The generated <code>Instances.Bindings</code> models use it; <code>OpcUaSupport.Loopback</code> implements it with a table.</p></html>"));
end ReadReal;
