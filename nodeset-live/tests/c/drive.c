/*
 * Scenario (a) of issue 39, component simulation, as a Modelica tool's generated code runs it: the external
 * objects made at initialisation, the sampled calls at each sample, the destructors at the end.
 *
 * The simulation integrates a first-order drive (explicit Euler, step 10 ms, time constant 0.2 s, target
 * 1 rad) for 2 s and publishes its position and speed every 50 ms through the server object, as
 * ParameterSet/ActualPosition and ParameterSet/ActualSpeed of the Robotics axis `Axis1` of the fixture
 * LiveAxis.NodeSet2.xml. A client object of its own, connected over Basic256Sha256 SignAndEncrypt as
 * `operator`, reads both back at each sample; an outside client (node-opcua, started by the test) subscribes
 * to them. Bad input through the same calls: an unknown NodeId, a wrong type.
 *
 * Usage: drive NODESETS SERVER_PKI CLIENT_PKI USERS_FILE PASSWORD_ENV
 * Prints `drive: listening on <url>` once the objects are made, then waits for a line on stdin before it
 * simulates (the outside client subscribes meanwhile); prints one `sample` line per sample, with the time of
 * the write call (`published=`, milliseconds since the Unix epoch), then `drive: simulated` and waits for a
 * second line before the destructors. Exits 0 when every check held.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "nodeset_live.h"

#define AXIS "nsu=http://example.com/nodeset-live/axis/;i="
#define POSITION AXIS "6001"
#define SPEED AXIS "6002"

static int failures = 0;

/*
 * The string allocator of a Modelica tool's runtime (ModelicaUtilities.h), which the library finds in the
 * process (the program is linked with -rdynamic, as a tool's simulation exports its runtime): every string
 * the library returns is allocated here, and the "tool" frees them all at the end, as a tool frees its
 * string stack.
 */
static char* strings[4096];
static int allocated = 0;

char* ModelicaAllocateStringWithErrorReturn(size_t len);
char* ModelicaAllocateStringWithErrorReturn(size_t len) {
    if (allocated == (int)(sizeof strings / sizeof strings[0])) {
        return NULL;
    }
    strings[allocated] = malloc(len + 1);
    return strings[allocated++];
}

static void expect(int ok, const char* what, const char* message) {
    if (!ok) {
        failures++;
        fprintf(stderr, "drive: FAILED: %s (%s)\n", what, message ? message : "");
    }
}

/* Milliseconds since the Unix epoch, as the subscriber's clock gives them. */
static double now_ms(void) {
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* Waits for a line on stdin (the test's go-ahead). */
static void wait_line(void) {
    char line[64];
    fflush(stdout);
    if (fgets(line, sizeof line, stdin) == NULL) {
        line[0] = '\0';
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
    printf("drive: listening on %s\n", url);
    wait_line();

    /* The simulation: dx/dt = (target - x)/T, sampled every 5 steps. */
    const double dt = 0.01, T = 0.2, target = 1.0;
    double x = 0.0, v = 0.0, read_x = 0.0, read_v = 0.0;
    int samples = 0;
    for (int step = 0; step <= 200; step++) {
        double t = step * dt;
        if (step % 5 == 0) {
            double published = now_ms();
            int st = opcua_live_server_write_real(server, POSITION, x);
            expect(st == 0, "publish ActualPosition", opcua_live_server_error(server));
            st = opcua_live_server_write_real(server, SPEED, v);
            expect(st == 0, "publish ActualSpeed", opcua_live_server_error(server));
            read_x = opcua_live_client_read_real(client, POSITION, read_x, &st);
            expect(st == 0 && read_x == x, "the client reads ActualPosition back", opcua_live_client_error(client));
            read_v = opcua_live_client_read_real(client, SPEED, read_v, &st);
            expect(st == 0 && read_v == v, "the client reads ActualSpeed back", opcua_live_client_error(client));
            printf("sample %d t=%.2f position=%.17g speed=%.17g read=%.17g,%.17g published=%.3f\n", samples, t, x, v,
                   read_x, read_v, published);
            samples++;
            /* A simulation that runs in real time: the next sample 50 ms later. */
            struct timespec pause = {0, 50 * 1000 * 1000};
            nanosleep(&pause, NULL);
        }
        v = (target - x) / T;
        x += v * dt;
    }
    double expected = 1.0 - pow(1.0 - dt / T, 201);
    expect(fabs(x - expected) < 1e-12, "the drive integrates as Euler says", "");
    printf("drive: simulated\n");
    wait_line();

    /* Bad input: a status and a message, the value held. */
    int st = 0;
    double held = opcua_live_client_read_real(client, AXIS "999999", 4.5, &st);
    expect(held == 4.5 && st != 0, "an unknown NodeId holds the value", "");
    printf("drive: unknown NodeId: status %d: %s\n", st, opcua_live_client_error(client));
    st = opcua_live_server_write_boolean(server, POSITION, 1);
    expect(st != 0 && strstr(opcua_live_server_error(server), "cannot write") != NULL, "a Boolean to a Double",
           opcua_live_server_error(server));
    printf("drive: wrong type: status %d: %s\n", st, opcua_live_server_error(server));

    const char* message = opcua_live_server_error(server);
    expect(allocated > 0 && message == strings[allocated - 1], "the messages are allocated by the tool", message);
    printf("drive: %d strings allocated by the tool\n", allocated);

    /* The end: the destructors; the tool's strings freed. */
    opcua_live_client_free(client);
    opcua_live_server_free(server);
    for (int i = 0; i < allocated; i++) {
        free(strings[i]);
    }
    printf("drive: %d samples, final position %.6f, %d failures\n", samples, x, failures);
    return failures == 0 ? 0 : 1;
}
