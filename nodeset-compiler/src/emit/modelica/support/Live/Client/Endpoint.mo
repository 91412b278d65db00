within OpcUaSupport.Live.Client;
model Endpoint "The OPC UA server the simulation connects to: declare it inner at the top of the model"
  parameter String url = "opc.tcp://localhost:4840/" "Endpoint URL of the server";
  parameter String policy = "Basic256Sha256" "Security policy: Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss, or None (servers started insecure, on loopback)";
  parameter String mode = "SignAndEncrypt" "Message security mode: SignAndEncrypt, Sign, or None with the policy None";
  parameter String pkiDir = "pki/simulation-client" "The client's PKI folder: its certificate is created in own/ on first use; trusted/ holds the server certificates it accepts";
  parameter String user = "" "User name; empty: anonymous";
  parameter String passwordEnv = "OPCUA_PASSWORD" "Name of the environment variable that holds the user's password (never the password itself)";
  parameter Boolean useBrowsePaths = false "Find each variable by its block's browsePath (translated by the server once per session) instead of its nodeId: for a server whose NodeIds differ from the nodesets'";
  final parameter OpcUaSupport.Live.Functions.ClientObject client = OpcUaSupport.Live.Functions.ClientObject(url, policy, mode, pkiDir, user, passwordEnv) "The client";
  annotation (defaultComponentName="opcuaClient", defaultComponentPrefixes="inner", {BLOCK_ICON}, Documentation(info="<html><p>Opens a session when the simulation
starts and closes it when it ends. A server that cannot be reached does not end the simulation: the blocks'
<code>status</code> outputs say so, and the client connects again in the background.</p></html>"));
end Endpoint;
