// A node-opcua client for nodeset-live/tests/c_abi.rs (scenario (a) of issue 39): subscribes to variables of a
// server over Basic256Sha256 SignAndEncrypt, as a user, and prints every data change it is notified of with the
// time it arrived.
// Usage: node subscribe.js URL CERT KEY PKI_DIR USER PASSWORD_ENV NODEID...
//   CERT, KEY: the client's certificate (DER) and private key (PEM), which the server already trusts;
//   PKI_DIR: node-opcua's certificate folder, whose trusted/certs/ holds the server's certificate (no
//   certificate is accepted unless it is there);
//   the password is read from the environment variable PASSWORD_ENV.
// Prints `ready` once every monitored item is created, then one line `change <index> <value> <ms>` per
// notification: the index of the NodeId in the arguments, the value (a Double, printed exactly), and the
// arrival time in milliseconds since the Unix epoch (performance.timeOrigin + performance.now(), sub-millisecond).
// Ends when its stdin closes: closes the session and prints `closed`. Exit status 0 when it could subscribe.
"use strict";
const {
    UserTokenType,
    AttributeIds,
    TimestampsToReturn,
    ClientMonitoredItem,
} = require("node-opcua");
const { connectSecurely } = require("./secure");

const [url, cert, key, pki, user, passwordEnv, ...nodeIds] = process.argv.slice(2);
if (!url || !cert || !key || !pki || !user || !passwordEnv || nodeIds.length === 0) {
    console.error("usage: node subscribe.js URL CERT KEY PKI_DIR USER PASSWORD_ENV NODEID...");
    process.exit(2);
}
const password = process.env[passwordEnv];
if (password === undefined) {
    console.error(`the environment variable ${passwordEnv} (the password of ${user}) is not set`);
    process.exit(2);
}

function now() {
    return performance.timeOrigin + performance.now();
}

async function main() {
    const { client, session } = await connectSecurely(url, {
        pki,
        acceptUnknownServer: false,
        applicationName: "nodeset-live node-opcua subscriber",
        applicationUri: "urn:nodeset-live:node-subscriber",
        cert,
        key,
        identity: { type: UserTokenType.UserName, userName: user, password },
    });
    const subscription = await session.createSubscription2({
        requestedPublishingInterval: 10,
        requestedLifetimeCount: 6000,
        requestedMaxKeepAliveCount: 100,
        maxNotificationsPerPublish: 0,
        publishingEnabled: true,
        priority: 1,
    });
    // `nsu=<uri>;<id>` as `ns=<index>;<id>`, the index from the server's NamespaceArray.
    const namespaces = await session.readNamespaceArray();
    const byIndex = (text) => {
        if (!text.startsWith("nsu=")) {
            return text;
        }
        const at = text.lastIndexOf(";");
        const uri = text.slice(4, at);
        const index = namespaces.indexOf(uri);
        if (index < 0) {
            throw new Error(`the server has no namespace ${uri}`);
        }
        return `ns=${index};${text.slice(at + 1)}`;
    };
    for (const [index, nodeId] of nodeIds.entries()) {
        const item = await ClientMonitoredItem.create(
            subscription,
            { nodeId: byIndex(nodeId), attributeId: AttributeIds.Value },
            { samplingInterval: 0, discardOldest: false, queueSize: 100 },
            TimestampsToReturn.Neither
        );
        item.on("changed", (dataValue) => {
            const at = now();
            console.log(`change ${index} ${dataValue.value.value} ${at.toFixed(3)}`);
        });
        item.on("err", (message) => console.log(`error ${index} ${message}`));
    }
    console.log("ready");
    await new Promise((resolve) => {
        process.stdin.on("end", resolve);
        process.stdin.on("close", resolve);
        process.stdin.resume();
    });
    await subscription.terminate();
    await session.close();
    await client.disconnect();
    console.log("closed");
}

main().then(
    () => process.exit(0),
    (e) => {
        console.error(e && e.message ? e.message : e);
        process.exit(1);
    }
);
