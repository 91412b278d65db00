within OpcUaSupport;
record Nodes "Nodes of an OPC UA server or client configuration, as in the DLR OPC UA library"
  String nsUri[:] = fill("", 0) "Namespace URIs; nsIndex i > 0 refers to nsUri[i]"
    annotation (Dialog(enable=true));
  Integer nVars = 0 "Number of variable nodes";
  VariableNode vars[nVars] "Variable nodes" annotation (Dialog(enable=true));
end Nodes;
