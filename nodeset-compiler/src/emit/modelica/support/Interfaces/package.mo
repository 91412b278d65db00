within OpcUaSupport;
package Interfaces "Blocks that read and write OPC UA variables, for an OPC UA library to implement"
  annotation ({PACKAGE_ICON}, Documentation(info="<html><p>Partial blocks that read and write Real, Integer,
Boolean and String variables of an OPC UA server, by NodeId (with a browse path to find the node where NodeIds
differ), and the <code>Connection</code> record they find as <code>outer</code>. They carry no code that talks
to a server: an OPC UA Modelica library (the DLR OPC UA library, or another) extends each block and gives the
equation of <code>value</code> (reads) or sends <code>value</code> (writes). The generated
<code>Instances.Bindings</code> models declare one block per variable of an instance, as a replaceable class
whose default is <code>OpcUaSupport.Loopback</code>; redeclare it with the implementation to bind the instance
to a server.</p></html>"));
end Interfaces;
