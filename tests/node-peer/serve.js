// A node-opcua server that serves NodeSet2 files as they are, for tests/tests/verify.rs: what `verify` finds
// on it is compared with what `check` finds in the files' static instances.
// Usage: node serve.js PORT FILE... (the base namespace's file first, then each file after the models it
// requires). Anonymous sessions, SecurityPolicy None. Prints `listening on <url>` when ready; stops on
// SIGTERM.
"use strict";
const { OPCUAServer } = require("node-opcua");

const port = parseInt(process.argv[2], 10);
const files = process.argv.slice(3);
if (!(port > 0) || files.length === 0) {
    console.error("usage: node serve.js PORT FILE...");
    process.exit(2);
}

async function main() {
    const server = new OPCUAServer({ port, nodeset_filename: files, allowAnonymous: true });
    await server.initialize();
    await server.start();
    console.log(`listening on opc.tcp://127.0.0.1:${port}/UA/NodeOPCUA`);
    const stop = async () => {
        await server.shutdown(0);
        process.exit(0);
    };
    process.on("SIGTERM", stop);
    process.on("SIGINT", stop);
}

main().catch((e) => {
    console.error(e);
    process.exit(1);
});
