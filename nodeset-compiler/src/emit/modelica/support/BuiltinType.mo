within OpcUaSupport;
type BuiltinType = enumeration(
    Boolean_ "Boolean (1)",
    SByte "SByte (2)",
    Byte "Byte (3)",
    Int16 "Int16 (4)",
    UInt16 "UInt16 (5)",
    Int32 "Int32 (6)",
    UInt32 "UInt32 (7)",
    Int64 "Int64 (8)",
    UInt64 "UInt64 (9)",
    Float "Float (10)",
    Double "Double (11)",
    String_ "String (12)",
    DateTime "DateTime (13)",
    Guid "Guid (14)",
    ByteString "ByteString (15)",
    XmlElement "XmlElement (16)",
    NodeId "NodeId (17)",
    ExpandedNodeId "ExpandedNodeId (18)",
    StatusCode "StatusCode (19)",
    QualifiedName "QualifiedName (20)",
    LocalizedText "LocalizedText (21)",
    ExtensionObject "ExtensionObject, the encoding of every structure (22)",
    DataValue "DataValue (23)",
    Variant "Variant (24)",
    DiagnosticInfo "DiagnosticInfo (25)")
  "The 25 built-in types of OPC UA Part 6; Integer(t) is the built-in type id"
  annotation (Documentation(info="<html><p>The built-in types of OPC UA Part 6, 5.1.2, in the order of their ids,
so that <code>Integer(t)</code> is the id. A variable's value is encoded as one of them; a structure is an
<code>ExtensionObject</code>. Boolean and String are the literals <code>Boolean_</code> and <code>String_</code>:
no literal is named like a predefined Modelica type.</p></html>"));
