/*
 * Scenario (b) of issue 39, interactive simulation and control, as a Modelica tool's generated code runs it:
 * the client object made at initialisation, the sampled reads and writes, the destructor at the end.
 *
 * The program connects to the robot example of nodeset-examples (Basic256Sha256 SignAndEncrypt, the
 * defaults, as `operator`, the password in the environment variable named), reads the six joint positions
 * by browse path (translated once by the server, then read by NodeId) every 100 ms for 0.5 s, converts each
 * from the engineering unit of the variable to SI as the generated blocks do (y = siFactor*value + siOffset,
 * the two numbers given on the command line as the binding's parameters give them), and writes the
 * controller's ConfiguredDefaultStopMode. Bad input through the same calls: a read-only variable written, a
 * Real written to an Int16, a joint the robot does not have.
 *
 * Usage: control URL CLIENT_PKI PASSWORD_ENV SI_FACTOR SI_OFFSET
 * Exits 3 with `control: not connected: status <n>: <message>` when the constructor could not open a
 * session (a certificate refused, say); else prints one `joint` line per joint and sample and `control: ...`
 * lines, and exits 0 when every check held.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "nodeset_live.h"

#define AXES "Robot/MotionDevices/Arm/Axes/A"
#define STOP_MODE "Robot/Controllers/Controller/SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode"
#define SPEED_OVERRIDE "Robot/MotionDevices/Arm/ParameterSet/SpeedOverride"

static int failures = 0;

static void expect(int ok, const char* what, const char* message) {
    if (!ok) {
        failures++;
        fprintf(stderr, "control: FAILED: %s (%s)\n", what, message ? message : "");
    }
}

/* The one place the engineering unit becomes SI, as OpcUaSupport.Interfaces.ReadReal says. */
static double to_si(double value, double factor, double offset) {
    return factor * value + offset;
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

int main(int argc, char** argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: control URL CLIENT_PKI PASSWORD_ENV SI_FACTOR SI_OFFSET\n");
        return 2;
    }
    const double factor = strtod(argv[4], NULL), offset = strtod(argv[5], NULL);
    /* Initialisation: the constructor. */
    void* client = opcua_live_client_new(argv[1], "", "", argv[2], "operator", argv[3]);
    int st = opcua_live_client_status(client);
    if (st != 0) {
        printf("control: not connected: status %d: %s\n", st, opcua_live_client_error(client));
        opcua_live_client_free(client);
        return 3;
    }

    /* The samples: six joints each. */
    char paths[6][96];
    for (int j = 0; j < 6; j++) {
        snprintf(paths[j], sizeof paths[j], AXES "%d/ParameterSet/ActualPosition", j + 1);
    }
    double held[6] = {0, 0, 0, 0, 0, 0};
    double busy = 0.0;
    int reads = 0;
    for (int sample = 0; sample < 5; sample++) {
        double start = now_s();
        for (int j = 0; j < 6; j++) {
            held[j] = opcua_live_client_read_real(client, paths[j], held[j], &st);
            expect(st == 0, paths[j], opcua_live_client_error(client));
            reads++;
        }
        busy += now_s() - start;
        for (int j = 0; j < 6; j++) {
            printf("joint %d %d value=%.17g si=%.17g\n", sample, j + 1, held[j], to_si(held[j], factor, offset));
        }
        struct timespec pause = {0, 100 * 1000 * 1000};
        nanosleep(&pause, NULL);
    }
    printf("control: %d joint reads, %.0f reads/s\n", reads, reads / busy);

    /* The control output: a settable variable written, and read back. */
    st = opcua_live_client_write_integer(client, STOP_MODE, 2);
    expect(st == 0, "write ConfiguredDefaultStopMode", opcua_live_client_error(client));
    int mode = opcua_live_client_read_integer(client, STOP_MODE, -1, &st);
    printf("control: ConfiguredDefaultStopMode %d status %d\n", mode, st);

    /* Bad input: a status and a message, never a crash. */
    st = opcua_live_client_write_real(client, SPEED_OVERRIDE, 0.5);
    printf("control: read-only: status %d: %s\n", st, opcua_live_client_error(client));
    st = opcua_live_client_write_real(client, STOP_MODE, 1.5);
    printf("control: wrong type: status %d: %s\n", st, opcua_live_client_error(client));
    double none = opcua_live_client_read_real(client, AXES "7/ParameterSet/ActualPosition", 4.5, &st);
    expect(none == 4.5, "a failed read holds the value", "");
    printf("control: no such joint: status %d: %s\n", st, opcua_live_client_error(client));

    /* The end: the destructor. */
    opcua_live_client_free(client);
    printf("control: %d failures\n", failures);
    return failures == 0 ? 0 : 1;
}
