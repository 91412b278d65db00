within OpcUaSupport.Loopback;
block WriteString "Keeps the String value written instead of sending it to a server"
  extends OpcUaSupport.Interfaces.WriteString;
  OpcUaSupport.StringOutput written = value "The OPC UA value written"
    annotation (Placement(transformation(extent={{100,-10},{120,10}})));
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>A write without a server: the OPC UA value the block would send is its output <code>written</code>, so that a test sees what a bound model writes.</p></html>"));
end WriteString;
