within OpcUaSupport;
type NodeIdType = enumeration(
    Numeric "Numeric identifier (i=...)",
    String "String identifier (s=...)",
    Guid "GUID identifier (g=...)",
    Opaque "Opaque identifier, base64 text (b=...)")
  "Kind of identifier of a NodeId";
