within OpcUaSupport.Live.Server;
model Endpoint "The OPC UA server the simulation runs: declare it inner at the top of the model"
  parameter Integer port = 4840 "TCP port; 0 picks a free one";
  parameter String nodesets = "" "NodeSet2 files of the namespaces to serve and folders of the models they require, separated by ';'";
  parameter String pkiDir = "pki/simulation" "The server's PKI folder: its certificate is created in own/ on first start; trusted/ holds the client certificates it accepts";
  parameter String usersFile = "" "The user file (nodeset-users); empty: anonymous sessions only, which may read but not write";
  parameter Boolean insecure = false "Add an endpoint without security where anonymous sessions may write: loopback tests only";
  final parameter OpcUaSupport.Live.Functions.ServerObject server = OpcUaSupport.Live.Functions.ServerObject(port, nodesets, pkiDir, usersFile, insecure) "The server";
initial algorithm
  assert(OpcUaSupport.Live.Functions.serverStatus(server) == 0, "the OPC UA server of the simulation cannot start: " + OpcUaSupport.Live.Functions.serverError(server));
  annotation (defaultComponentName="opcuaServer", defaultComponentPrefixes="inner", {BLOCK_ICON}, Documentation(info="<html><p>Starts the server when the
simulation starts and stops it when it ends. A server that cannot start (a nodeset that does not compile, a
port in use, a PKI folder it cannot write) ends the simulation at initialisation with the reason.</p></html>"));
end Endpoint;
