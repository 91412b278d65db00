// A node-opcua client for tests/tests/verify.rs: browses everything below Objects/<FOLDER> of a server
// and reads the value of every variable found there.
// Usage: node browse.js URL FOLDER PKI_DIR. Connects over Basic256Sha256 SignAndEncrypt, anonymously, with its
// own certificate in PKI_DIR (created on first use; the server's certificate is accepted). Prints one line
// `bad <status> <nodeId> <browse path>` per variable whose value read is neither Good nor Uncertain, one line
// `empty <nodeId> <browse path> <DataType>` per variable without a value, one line `state <browse path> <text>` per
// CurrentState variable, then
// `objects <n> variables <n> methods <n> good <n> uncertain <n> bad <n> empty <n>`. Exit status 0 when it could browse
// and read, 1 otherwise.
"use strict";
const {
    BrowseDirection,
    NodeClass,
    AttributeIds,
    DataType,
} = require("node-opcua");
const { connectSecurely } = require("./secure");

const [url, folder, pki] = process.argv.slice(2);
if (!url || !folder || !pki) {
    console.error("usage: node browse.js URL FOLDER PKI_DIR");
    process.exit(2);
}

async function browseAll(session, nodeId) {
    const out = [];
    let result = await session.browse({
        nodeId,
        browseDirection: BrowseDirection.Forward,
        referenceTypeId: "HierarchicalReferences",
        includeSubtypes: true,
        nodeClassMask: 0,
        resultMask: 63,
    });
    out.push(...(result.references || []));
    while (result.continuationPoint && result.continuationPoint.length > 0) {
        const next = await session.browseNext([result.continuationPoint], false);
        result = next[0];
        out.push(...(result.references || []));
    }
    return out;
}

async function main() {
    const { client, session } = await connectSecurely(url, {
        pki,
        acceptUnknownServer: true,
        applicationName: "nodeset-compiler node-opcua browse",
    });
    const top = (await browseAll(session, "ns=0;i=85")).filter((r) => r.browseName.name === folder);
    if (top.length !== 1) {
        throw new Error(`Objects has ${top.length} children named ${folder}`);
    }
    const counts = { objects: 0, variables: 0, methods: 0, good: 0, uncertain: 0, bad: 0, empty: 0 };
    const variables = [];
    const seen = new Set();
    const stack = [[top[0].nodeId.toString(), folder]];
    while (stack.length > 0) {
        const [id, where] = stack.pop();
        if (seen.has(id)) {
            continue;
        }
        seen.add(id);
        for (const r of await browseAll(session, id)) {
            const child = r.nodeId.toString();
            const childPath = `${where}/${r.browseName.name}`;
            if (r.nodeClass === NodeClass.Variable) {
                variables.push([child, childPath]);
            } else if (r.nodeClass === NodeClass.Object) {
                counts.objects += 1;
            } else if (r.nodeClass === NodeClass.Method) {
                counts.methods += 1;
            }
            if (!seen.has(child) && r.nodeId.namespace !== 0) {
                stack.push([child, childPath]);
            }
        }
    }
    const unique = [...new Map(variables).entries()].sort();
    counts.variables = unique.length;
    for (let i = 0; i < unique.length; i += 500) {
        const batch = unique.slice(i, i + 500);
        const values = await session.read(batch.map(([nodeId]) => ({ nodeId, attributeId: AttributeIds.Value })));
        const types = await session.read(batch.map(([nodeId]) => ({ nodeId, attributeId: AttributeIds.DataType })));
        values.forEach((v, k) => {
            const s = v.statusCode;
            if (batch[k][1].endsWith("/CurrentState")) {
                console.log(`state ${batch[k][1]} ${v.value.value ? v.value.value.text : ""}`);
            }
            if (v.value.dataType === DataType.Null) {
                counts.empty += 1;
                console.log(`empty ${batch[k][0]} ${batch[k][1]} ${types[k].value.value ? types[k].value.value.toString() : "?"}`);
            }
            // The severity is the top two bits: 00 Good, 01 Uncertain, 10 Bad.
            const severity = s.value >>> 30;
            if (severity === 0) {
                counts.good += 1;
            } else if (severity === 1) {
                counts.uncertain += 1;
            } else {
                counts.bad += 1;
                console.log(`bad ${s.name} ${batch[k][0]} ${batch[k][1]}`);
            }
        });
    }
    console.log(Object.entries(counts).map(([k, n]) => `${k} ${n}`).join(" "));
    await session.close();
    await client.disconnect();
}

main().then(
    () => process.exit(0),
    (e) => {
        console.error(e && e.message ? e.message : e);
        process.exit(1);
    }
);
