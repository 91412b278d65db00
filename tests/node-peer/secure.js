// The secure connection both node-opcua clients of the tests open (browse.js, subscribe.js): Basic256Sha256
// SignAndEncrypt, node-opcua's certificate folder PKI_DIR, a few quick retries.
// `connectSecurely(url, { pki, acceptUnknownServer, applicationName, applicationUri, cert, key, identity })`:
//   acceptUnknownServer: whether a server certificate not in PKI_DIR/trusted/certs is accepted;
//   cert, key: the client's certificate (DER) and private key (PEM); node-opcua makes its own in PKI_DIR if absent;
//   identity: the session's user identity (node-opcua's UserIdentityInfo), anonymous if absent.
// Resolves to { client, session }; rejects with node-opcua's error when the connection or the session fails.
"use strict";
const path = require("path");
const { OPCUAClient, OPCUACertificateManager, MessageSecurityMode, SecurityPolicy } = require("node-opcua");

async function connectSecurely(url, options) {
    const clientCertificateManager = new OPCUACertificateManager({
        rootFolder: path.resolve(options.pki),
        automaticallyAcceptUnknownCertificate: options.acceptUnknownServer,
    });
    const client = OPCUAClient.create({
        applicationName: options.applicationName,
        applicationUri: options.applicationUri,
        securityMode: MessageSecurityMode.SignAndEncrypt,
        securityPolicy: SecurityPolicy.Basic256Sha256,
        certificateFile: options.cert && path.resolve(options.cert),
        privateKeyFile: options.key && path.resolve(options.key),
        endpointMustExist: false,
        clientCertificateManager,
        connectionStrategy: { maxRetry: 2, initialDelay: 200, maxDelay: 1000 },
    });
    await client.connect(url);
    const session = await client.createSession(options.identity);
    return { client, session };
}

module.exports = { connectSecurely };
