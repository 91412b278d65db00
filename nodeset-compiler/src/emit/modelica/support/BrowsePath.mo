within OpcUaSupport;
record BrowsePath "A node reached by BrowseNames from a start node"
  String startNodeId = "i=85" "NodeId of the start node (default: the ObjectsFolder)";
  String path = "" "BrowseNames separated by '/'; a '/' or '&' inside a name is written '&/' or '&&'";
  annotation ({RECORD_ICON}, Documentation(info="<html><p>Generated components carry a <code>browsePath</code> relative to the
object their enclosing class stands for: the path of a nested component is the path of its parent component, a
'/', and its own path. Like the DLR OPC UA library, a path names BrowseNames without their namespace.</p></html>"));
end BrowsePath;
