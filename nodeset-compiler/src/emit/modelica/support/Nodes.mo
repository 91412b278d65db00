within OpcUaSupport;
record Nodes "Nodes of an OPC UA server or client configuration, as in the DLR OPC UA library"
  String nsUri[:] = fill("", 0) "Namespace URIs; nsIndex i > 0 refers to nsUri[i]"
    annotation (Dialog(enable=true));
  Integer nVars = 0 "Number of variable nodes";
  VariableNode vars[nVars] "Variable nodes" annotation (Dialog(enable=true));
  annotation ({RECORD_ICON}, Documentation(info="<html><p>The variables of an address space, as the configuration record of
an OPC UA server or client block of the DLR OPC UA library. The generated <code>Instances.Objects</code> model of
each namespace fills one with every variable of its instances. <code>vars</code> is sized by
<code>nVars</code>, because an unsized array of records inside a record is not accepted by every Modelica
tool.</p></html>"));
end Nodes;
