/*
 * nodeset_live.h: the C interface of nodeset-live, the live OPC UA binding of the Modelica packages that
 * nodeset-compiler generates (OpcUaSupport.Live).
 *
 * The types follow the Modelica external function interface (MLS 12.9): Real is double, Integer and
 * Boolean are int, String is const char*, an external object is a void* made by its constructor and
 * released by its destructor. Every read and write takes a NodeId string: nsu=<namespace URI>;i=<n>
 * (also s=, g=, b=), ns=<index>;i=<n>, or i=<n>; a client's also take a browse path from the ObjectsFolder
 * (BrowseNames separated by '/', no '='), which the server translates once per session.
 *
 * Status: 0 is Good; anything else is the OPC UA status code's 32 bits (negative for Bad). A failed read
 * returns `previous`, so a sampled block holds its value. The message of the last call on an object is
 * opcua_live_server_error / opcua_live_client_error ("" after a call that succeeded). The library never
 * calls ModelicaError itself: the Modelica functions of OpcUaSupport.Live pass the message on.
 *
 * Strings returned (messages, String values): where the process has ModelicaAllocateStringWithErrorReturn
 * (a Modelica tool's runtime), a copy allocated by it, which the tool owns; else a copy in a buffer of the
 * calling thread, valid until that thread's next call that returns a string (MLS 12.9.6).
 *
 * Constructors never return NULL (but on allocation failure): an object that could not start reports
 * why through its status and message. No function lets a Rust panic unwind into the caller.
 *
 * Kept in step with nodeset-live/src/lib.rs by nodeset-live/tests/header/mod.rs.
 */
#ifndef NODESET_LIVE_H
#define NODESET_LIVE_H

#ifdef __cplusplus
extern "C" {
#endif

/* Server: component simulation. */
void* opcua_live_server_new(int port, const char* nodesets, const char* pkiDir, const char* usersFile, int insecure);
void opcua_live_server_free(void* server);
int opcua_live_server_status(void* server);
int opcua_live_server_port(void* server);
const char* opcua_live_server_error(void* server);
double opcua_live_server_read_real(void* server, const char* nodeId, double previous, int* status);
int opcua_live_server_read_integer(void* server, const char* nodeId, int previous, int* status);
int opcua_live_server_read_boolean(void* server, const char* nodeId, int previous, int* status);
int opcua_live_server_write_real(void* server, const char* nodeId, double value);
int opcua_live_server_write_integer(void* server, const char* nodeId, int value);
int opcua_live_server_write_boolean(void* server, const char* nodeId, int value);
const char* opcua_live_server_read_string(void* server, const char* nodeId, const char* previous, int* status);
int opcua_live_server_write_string(void* server, const char* nodeId, const char* value);

/* Client: interactive simulation and control. */
void* opcua_live_client_new(const char* url, const char* policy, const char* mode, const char* pkiDir, const char* user, const char* passwordEnv);
void opcua_live_client_free(void* client);
int opcua_live_client_status(void* client);
const char* opcua_live_client_error(void* client);
double opcua_live_client_read_real(void* client, const char* nodeId, double previous, int* status);
int opcua_live_client_read_integer(void* client, const char* nodeId, int previous, int* status);
int opcua_live_client_read_boolean(void* client, const char* nodeId, int previous, int* status);
int opcua_live_client_write_real(void* client, const char* nodeId, double value);
int opcua_live_client_write_integer(void* client, const char* nodeId, int value);
int opcua_live_client_write_boolean(void* client, const char* nodeId, int value);
const char* opcua_live_client_read_string(void* client, const char* nodeId, const char* previous, int* status);
int opcua_live_client_write_string(void* client, const char* nodeId, const char* value);

#ifdef __cplusplus
}
#endif

#endif /* NODESET_LIVE_H */
