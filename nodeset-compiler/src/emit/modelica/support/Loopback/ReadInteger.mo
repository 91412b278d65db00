within OpcUaSupport.Loopback;
block ReadInteger "Reads the initial Integer value instead of asking a server"
  extends OpcUaSupport.Interfaces.ReadInteger;
equation
  value = initValue;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>A read without a server: <code>value</code> is <code>initValue</code>, the value the nodeset gives the variable. It stands in for a server in simulations and tests of bound models.</p></html>"));
end ReadInteger;
