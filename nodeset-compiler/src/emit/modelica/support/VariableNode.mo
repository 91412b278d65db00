within OpcUaSupport;
record VariableNode "A variable node of the Nodes configuration record"
  Integer nsIndex = 1 "Namespace: 0 is the OPC UA base namespace, i > 0 is Nodes.nsUri[i]";
  NodeIdType nodeIdType = NodeIdType.Numeric "Kind of identifier";
  String id = "" "Identifier as text";
  String displayName = "" "DisplayName";
  String description = "" "Description";
  BuiltinType dataType = BuiltinType.Double "Built-in type the value is encoded as";
  String dataTypeId = "" "NodeId of the DataType (nsu= form outside the base namespace)";
  String arrayDimensions = "" "Comma-separated array lengths (0: any length); empty for a scalar";
  String initValue = "" "Initial value as text; empty when the node has none or it is a structure";
  String browsePath = "" "BrowseNames from the ObjectsFolder, separated by '/'";
  annotation ({RECORD_ICON}, Documentation(info="<html><p>One variable of an OPC UA address space as the DLR OPC UA library
configures it (Sch&ouml;nfeld et al., Modelica Conference 2021): its NodeId (<code>nsIndex</code>,
<code>nodeIdType</code>, <code>id</code>), names, built-in type and initial value. Values are those of OPC UA,
in the variable's engineering unit (a generated model holds SI values; its <code>__OPCUA</code> annotation
gives the conversion). <code>browsePath</code> is ours: it finds the node on a server whose NodeIds differ.</p></html>"));
end VariableNode;
