within OpcUaSupport;
record NodeId "A NodeId, split as in the DLR OPC UA library"
  Integer nsIndex = 0 "Namespace: 0 is the OPC UA base namespace, i > 0 is Nodes.nsUri[i]";
  NodeIdType nodeIdType = NodeIdType.Numeric "Kind of identifier";
  String id = "" "Identifier as text (the number of a Numeric identifier)";
  annotation ({RECORD_ICON}, Documentation(info="<html><p>Generated code writes NodeIds as text in the standard
<code>nsu=&lt;namespace URI&gt;;i=&lt;number&gt;</code> form (<code>i=&lt;number&gt;</code> in the base
namespace); this record is the split form that server and client blocks take as parameters.</p></html>"));
end NodeId;
