within OpcUaSupport;
type NodeIdType = enumeration(
    Numeric "Numeric identifier (i=...)",
    String_ "String identifier (s=...)",
    Guid "GUID identifier (g=...)",
    Opaque "Opaque identifier, base64 text (b=...)")
  "Kind of identifier of a NodeId"
  annotation (Documentation(info="<html><p>The four kinds of NodeId identifier of OPC UA Part 3, 8.2.3, as in the
<code>nodeIdType</code> parameter of the DLR OPC UA library. The literal for string identifiers is
<code>String_</code>: no literal is named like a predefined Modelica type.</p></html>"));
