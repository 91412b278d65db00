within OpcUaSupport.Loopback;
block ReadBoolean "Reads the initial Boolean value instead of asking a server"
  extends OpcUaSupport.Interfaces.ReadBoolean;
equation
  value = initValue;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>A read without a server: <code>value</code> is <code>initValue</code>, the value the nodeset gives the variable. It stands in for a server in simulations and tests of bound models.</p></html>"));
end ReadBoolean;
