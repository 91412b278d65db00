/*
 * The component-simulation scenario of issue 39 as a Modelica tool's generated code runs it: the external
 * objects made at initialisation, the sampled calls at each sample, the destructors at the end.
 *
 * The simulation integrates a first-order drive (explicit Euler, step 10 ms, time constant 0.2 s, target
 * 1 rad) for 2 s and publishes its position and speed every 50 ms through the server object: the position as
 * ActualPosition of axis 1 of the RobotCell robot, the speed as the fixture's Drive/Speed (ActualSpeed is
 * Optional in Robotics and absent from that instance). A client object, connected over Basic256Sha256
 * SignAndEncrypt as `operator`, reads both back at each sample. Bad input through the same calls: an
 * unknown NodeId, a wrong type.
 *
 * Usage: drive NODESETS SERVER_PKI CLIENT_PKI USERS_FILE PASSWORD_ENV
 * Prints one `sample` line per sample and `drive: ...` lines; exits 0 when every check held.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "nodeset_live.h"

#define POSITION "nsu=http://nodeset-compiler.dev/RobotCell/;i=4119"
#define SPEED "nsu=http://example.com/nodeset-live/;i=6002"

static int failures = 0;

static void expect(int ok, const char* what, const char* message) {
    if (!ok) {
        failures++;
        fprintf(stderr, "drive: FAILED: %s (%s)\n", what, message ? message : "");
    }
}

int main(int argc, char** argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: drive NODESETS SERVER_PKI CLIENT_PKI USERS_FILE PASSWORD_ENV\n");
        return 2;
    }
    /* Initialisation: the constructors. */
    void* server = opcua_live_server_new(0, argv[1], argv[2], argv[4], 0);
    if (opcua_live_server_status(server) != 0) {
        fprintf(stderr, "drive: the server did not start: %s\n", opcua_live_server_error(server));
        opcua_live_server_free(server);
        return 1;
    }
    char url[64];
    snprintf(url, sizeof url, "opc.tcp://127.0.0.1:%d/", opcua_live_server_port(server));
    void* client = opcua_live_client_new(url, "Basic256Sha256", "SignAndEncrypt", argv[3], "operator", argv[5]);
    expect(opcua_live_client_status(client) == 0, "the client connects", opcua_live_client_error(client));

    /* The simulation: dx/dt = (target - x)/T, sampled every 5 steps. */
    const double dt = 0.01, T = 0.2, target = 1.0;
    double x = 0.0, v = 0.0, read_x = 0.0, read_v = 0.0;
    int samples = 0;
    for (int step = 0; step <= 200; step++) {
        double t = step * dt;
        if (step % 5 == 0) {
            int st = opcua_live_server_write_real(server, POSITION, x);
            expect(st == 0, "publish ActualPosition", opcua_live_server_error(server));
            st = opcua_live_server_write_real(server, SPEED, v);
            expect(st == 0, "publish Speed", opcua_live_server_error(server));
            read_x = opcua_live_client_read_real(client, POSITION, read_x, &st);
            expect(st == 0 && read_x == x, "the client reads ActualPosition back", opcua_live_client_error(client));
            read_v = opcua_live_client_read_real(client, SPEED, read_v, &st);
            expect(st == 0 && read_v == v, "the client reads Speed back", opcua_live_client_error(client));
            printf("sample %d t=%.2f position=%.6f speed=%.6f read=%.6f,%.6f\n", samples, t, x, v, read_x, read_v);
            samples++;
        }
        v = (target - x) / T;
        x += v * dt;
    }
    double expected = 1.0 - pow(1.0 - dt / T, 201);
    expect(fabs(x - expected) < 1e-12, "the drive integrates as Euler says", "");

    /* Bad input: a status and a message, the value held. */
    int st = 0;
    double held = opcua_live_client_read_real(client, "nsu=http://nodeset-compiler.dev/RobotCell/;i=999999", 4.5, &st);
    expect(held == 4.5 && st != 0, "an unknown NodeId holds the value", "");
    printf("drive: unknown NodeId: status %d: %s\n", st, opcua_live_client_error(client));
    st = opcua_live_server_write_boolean(server, POSITION, 1);
    expect(st != 0 && strstr(opcua_live_server_error(server), "cannot write") != NULL, "a Boolean to a Double", opcua_live_server_error(server));
    printf("drive: wrong type: status %d: %s\n", st, opcua_live_server_error(server));

    /* The end: the destructors. */
    opcua_live_client_free(client);
    opcua_live_server_free(server);
    printf("drive: %d samples, final position %.6f, %d failures\n", samples, x, failures);
    return failures == 0 ? 0 : 1;
}
