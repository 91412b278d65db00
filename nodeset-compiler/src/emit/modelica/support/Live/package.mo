within OpcUaSupport;
package Live "The read and write blocks bound live to OPC UA: the simulation as a server, or as a client of a real one"
  package Functions "The external objects and functions of the nodeset_live library"
    class ServerObject "An OPC UA server run by the simulation"
      extends ExternalObject;
      function constructor "Starts the server of the namespaces of the nodesets"
        input Integer port "TCP port; 0 picks a free one";
        input String nodesets "NodeSet2 files to serve and folders of the models they require, separated by ';'";
        input String pkiDir "The server's PKI folder (own certificate, trusted client certificates)";
        input String usersFile "The user file; empty: anonymous sessions only, which may read";
        input Boolean insecure "Add an endpoint without security where anonymous sessions may write (loopback tests only)";
        output ServerObject server "The server";
      external "C" server = opcua_live_server_new(port, nodesets, pkiDir, usersFile, insecure)
        annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
      end constructor;

      function destructor "Stops the server"
        input ServerObject server "The server";
      external "C" opcua_live_server_free(server)
        annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
      end destructor;
    end ServerObject;

    class ClientObject "A session of the simulation to an OPC UA server"
      extends ExternalObject;
      function constructor "Connects to the server (and connects again when the connection is lost)"
        input String url "Endpoint URL, opc.tcp://host:port/";
        input String policy "Security policy: Basic256Sha256 (empty), Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss or None";
        input String mode "Message security mode: SignAndEncrypt (empty), Sign or None";
        input String pkiDir "The client's PKI folder (own certificate, trusted server certificates)";
        input String user "User name; empty: anonymous";
        input String passwordEnv "Name of the environment variable that holds the user's password";
        output ClientObject client "The client";
      external "C" client = opcua_live_client_new(url, policy, mode, pkiDir, user, passwordEnv)
        annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
      end constructor;

      function destructor "Disconnects"
        input ClientObject client "The client";
      external "C" opcua_live_client_free(client)
        annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
      end destructor;
    end ClientObject;

    impure function serverReadReal "Reads a Real variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Real previous "Returned when the read fails";
      output Real value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_server_read_real(server, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverReadReal;
    impure function serverWriteReal "Writes a Real variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Real value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_server_write_real(server, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverWriteReal;
    impure function serverReadInteger "Reads a Integer variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Integer previous "Returned when the read fails";
      output Integer value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_server_read_integer(server, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverReadInteger;
    impure function serverWriteInteger "Writes a Integer variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Integer value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_server_write_integer(server, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverWriteInteger;
    impure function serverReadBoolean "Reads a Boolean variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Boolean previous "Returned when the read fails";
      output Boolean value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_server_read_boolean(server, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverReadBoolean;
    impure function serverWriteBoolean "Writes a Boolean variable through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Boolean value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_server_write_boolean(server, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverWriteBoolean;
    impure function serverReadString "Reads a String variable (or the text of a LocalizedText) through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input String previous "Returned when the read fails";
      output String value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_server_read_string(server, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverReadString;
    impure function serverWriteString "Writes a String variable (or a LocalizedText, without locale) through the server object"
      input ServerObject server "The server";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input String value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_server_write_string(server, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverWriteString;
    impure function serverStatus "0 when the server runs; else the OPC UA status code saying why not"
      input ServerObject server "The server";
      output Integer status "0: Good";
    external "C" status = opcua_live_server_status(server)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverStatus;
    impure function serverError "The message of the last call on the server object (empty after a call that succeeded)"
      input ServerObject server "The server";
      output String message "The message";
    external "C" message = opcua_live_server_error(server)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end serverError;
    impure function clientReadReal "Reads a Real variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Real previous "Returned when the read fails";
      output Real value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_client_read_real(client, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientReadReal;
    impure function clientWriteReal "Writes a Real variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Real value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_client_write_real(client, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientWriteReal;
    impure function clientReadInteger "Reads a Integer variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Integer previous "Returned when the read fails";
      output Integer value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_client_read_integer(client, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientReadInteger;
    impure function clientWriteInteger "Writes a Integer variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Integer value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_client_write_integer(client, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientWriteInteger;
    impure function clientReadBoolean "Reads a Boolean variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Boolean previous "Returned when the read fails";
      output Boolean value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_client_read_boolean(client, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientReadBoolean;
    impure function clientWriteBoolean "Writes a Boolean variable through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input Boolean value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_client_write_boolean(client, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientWriteBoolean;
    impure function clientReadString "Reads a String variable (or the text of a LocalizedText) through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input String previous "Returned when the read fails";
      output String value "The value read, or previous";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" value = opcua_live_client_read_string(client, nodeId, previous, status)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientReadString;
    impure function clientWriteString "Writes a String variable (or a LocalizedText, without locale) through the client object"
      input ClientObject client "The client";
      input String nodeId "NodeId: nsu=<namespace URI>;i=<number>, ns=<index>;i=<number> or i=<number>";
      input String value "The value to write";
      output Integer status "0: Good; else the OPC UA status code (negative for Bad)";
    external "C" status = opcua_live_client_write_string(client, nodeId, value)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientWriteString;
    impure function clientStatus "0 when the client runs (a session is open); else the OPC UA status code saying why not"
      input ClientObject client "The client";
      output Integer status "0: Good";
    external "C" status = opcua_live_client_status(client)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientStatus;
    impure function clientError "The message of the last call on the client object (empty after a call that succeeded)"
      input ClientObject client "The client";
      output String message "The message";
    external "C" message = opcua_live_client_error(client)
      annotation (Library="nodeset_live", Include="#include \"nodeset_live.h\"", IncludeDirectory="modelica://OpcUaSupport/Resources/Include", LibraryDirectory="modelica://OpcUaSupport/Resources/Library");
    end clientError;
    function report "Passes a failed read or write on: an error when stop is true, else a warning"
      input Boolean stop "Whether the simulation stops";
      input String what "What failed";
      input String message "Why";
    algorithm
      assert(not stop, "OPC UA: " + what + ": " + message);
      assert(stop, "OPC UA: " + what + ": " + message, AssertionLevel.warning);
    end report;
    annotation ({PACKAGE_ICON}, Documentation(info="<html><p>The interface of the shared library
<code>nodeset_live</code> (<code>Resources/Include/nodeset_live.h</code>), after the Modelica external
function interface: <code>Real</code> is <code>double</code>, <code>Integer</code> and <code>Boolean</code>
are <code>int</code>, <code>String</code> is <code>const char*</code>, and each object is an
<code>ExternalObject</code> with its constructor and destructor. A read returns <code>previous</code> when it
fails; every call gives a status, 0 for Good, else the OPC UA status code, and <code>serverError</code> and
<code>clientError</code> the message of the last call, which the blocks pass to <code>assert</code>. The
library never ends the simulation itself.</p></html>"));
  end Functions;
  annotation ({PACKAGE_ICON}, Documentation(info="<html><p>An implementation of
<code>OpcUaSupport.Interfaces</code> bound to OPC UA by the shared library <code>nodeset_live</code>, built from
the <code>nodeset-live</code> crate of nodeset-compiler (<code>cargo build --release -p nodeset-live</code>)
and placed in <code>OpcUaSupport/Resources/Library/&lt;platform&gt;</code> (<code>linux64/libnodeset_live.so</code>,
<code>win64/nodeset_live.dll</code>); its header is <code>Resources/Include/nodeset_live.h</code>. The two
uses of the DLR OPC UA library (Sch&ouml;nfeld et al., Modelica Conference 2021):</p>
<ul>
<li><code>Server</code>: component simulation. <code>inner Live.Server.Endpoint opcuaServer(nodesets=...)</code>
serves the namespaces of the nodesets the package was generated from (their files are a parameter: the library
builds the address space from them at start, so it serves any generated package), secure by default with its
PKI folder and user file. Write blocks publish the simulation's values; read blocks return what clients
wrote.</li>
<li><code>Client</code>: interactive simulation and control. <code>inner Live.Client.Endpoint
opcuaClient(url=...)</code> connects to a real server, Basic256Sha256 SignAndEncrypt by default, as a user
whose password is read from an environment variable, never from the model. A lost connection is reported and
retried in the background.</li>
</ul>
<p>The blocks are sampled every <code>connection.samplePeriod</code> and hold their value between samples.
A failed read or write sets the block's <code>status</code> output (0 is Good, else the OPC UA status code)
and gives a warning with the reason; with <code>stopOnError = true</code> it ends the simulation with that
message. Bind a generated instance by redeclaring the block classes of its <code>Bindings</code> model:</p>
<pre>model Cell
  inner parameter OpcUaSupport.Interfaces.Connection connection(samplePeriod=0.05);
  inner OpcUaSupport.Live.Server.Endpoint opcuaServer(port=4840, nodesets=\"nodesets/Cell.NodeSet2.xml;nodesets/vendor\",
    usersFile=\"users.txt\");
  NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell cell(
    redeclare block ReadReal = OpcUaSupport.Live.Server.ReadReal,
    redeclare block WriteReal = OpcUaSupport.Live.Server.WriteReal);
end Cell;</pre>
<p>The library reads and writes Real, Integer, Boolean and String values (a String also reads and writes a
LocalizedText's text). A String it returns is allocated with the tool's
<code>ModelicaAllocateStringWithErrorReturn</code> where the simulation exports it, else kept in a buffer of the
calling thread until its next call that returns a string. A client's blocks find their variable by
<code>nodeId</code>, or by <code>browsePath</code> when <code>opcuaClient.useBrowsePaths = true</code>: the
server translates each path once per session, so a server whose NodeIds differ from the nodesets' is still
reached.</p></html>"));
end Live;
