"""Security of a generated server, checked with python asyncua (a third-party client).

Run against the example server started with `--demo --pki PKI --users USERS` (secure by default):

    security_check.py --url URL --pki PKI --work DIR --user op --password PW --observer obs --observer-password PW2

- the server offers no SecurityPolicy None endpoint (or, with --expect-none, one);
- a client certificate the server does not trust is refused and lands in PKI/rejected/; moved to
  PKI/trusted/ (what an administrator does), it is accepted;
- SignAndEncrypt with Basic256Sha256, Aes128_Sha256_RsaOaep and Aes256_Sha256_RsaPss and a user name works;
- a wrong password is refused;
- an anonymous session may read, and is refused writes and calls with BadUserAccessDenied;
- an Operator may write and call; an Observer (authenticated, no Operator role) may not write.

It prints one line per check and ends with `N passed, M failed`.
"""

import argparse
import asyncio
import shutil
import sys
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto import cert_gen, security_policies
from cryptography.x509.oid import ExtendedKeyUsageOID

DEMO_NS = "urn:nodeset-models:demo"
APP_URI = "urn:nodeset-tests:security-check"

POLICIES = {
    "Basic256Sha256": security_policies.SecurityPolicyBasic256Sha256,
    "Aes128_Sha256_RsaOaep": security_policies.SecurityPolicyAes128Sha256RsaOaep,
    "Aes256_Sha256_RsaPss": security_policies.SecurityPolicyAes256Sha256RsaPss,
}


class Report:
    def __init__(self) -> None:
        self.passed = 0
        self.failed = 0

    def check(self, name: str, ok: bool, detail: str = "") -> bool:
        if ok:
            self.passed += 1
            print(f"ok   {name}")
        else:
            self.failed += 1
            print(f"FAIL {name}: {detail}")
        return ok


def status_name(e: BaseException) -> str:
    if isinstance(e, ua.UaStatusCodeError):
        return ua.StatusCode(e.code).name
    return f"{type(e).__name__}: {e}"


async def make_cert(work: Path, name: str) -> tuple[Path, Path]:
    key, cert = work / f"{name}.pem", work / f"{name}.der"
    if not cert.exists():
        await cert_gen.setup_self_signed_certificate(
            key, cert, APP_URI, "localhost",
            [ExtendedKeyUsageOID.CLIENT_AUTH], {"commonName": f"security-check {name}"},
        )
    return cert, key


async def secure_client(url: str, policy: str, cert: Path, key: Path, user=None, password=None) -> Client:
    client = Client(url, timeout=10)
    client.application_uri = APP_URI
    if user is not None:
        client.set_user(user)
        client.set_password(password)
    await client.set_security(POLICIES[policy], str(cert), str(key), mode=ua.MessageSecurityMode.SignAndEncrypt)
    return client


async def demo_nodes(client: Client):
    ns = (await client.get_namespace_array()).index(DEMO_NS)
    return ua.NodeId(5001, ns), ua.NodeId(5000, ns), ua.NodeId(5008, ns)


async def write_status(client: Client, node: ua.NodeId, value: float) -> str:
    try:
        await client.get_node(node).write_value(ua.DataValue(ua.Variant(value, ua.VariantType.Double)))
        return "Good"
    except Exception as e:  # noqa: BLE001 - the status is what is checked
        return status_name(e)


async def call_status(client: Client, obj: ua.NodeId, method: ua.NodeId) -> str:
    req = ua.CallMethodRequest()
    req.ObjectId, req.MethodId = obj, method
    req.InputArguments = [ua.Variant(30.0, ua.VariantType.Double), ua.Variant(10, ua.VariantType.Int32)]
    return ua.StatusCode((await client.uaclient.call([req]))[0].StatusCode.value).name


async def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--url", required=True)
    p.add_argument("--pki", required=True, type=Path)
    p.add_argument("--work", required=True, type=Path)
    p.add_argument("--user", required=True)
    p.add_argument("--password", required=True)
    p.add_argument("--observer", required=True)
    p.add_argument("--observer-password", required=True)
    p.add_argument("--expect-none", action="store_true")
    a = p.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    r = Report()

    # Endpoints.
    probe = Client(a.url, timeout=10)
    endpoints = await probe.connect_and_get_server_endpoints()
    offered = sorted({(e.SecurityPolicyUri.rsplit("#", 1)[-1], e.SecurityMode.name) for e in endpoints})
    print("endpoints:", offered)
    has_none = any(e.SecurityMode == ua.MessageSecurityMode.None_ for e in endpoints)
    if a.expect_none:
        r.check("--insecure adds a SecurityPolicy None endpoint", has_none, str(offered))
    else:
        r.check("no SecurityPolicy None endpoint", not has_none, str(offered))
    for policy in POLICIES:
        for mode in ("Sign", "SignAndEncrypt"):
            r.check(f"endpoint {policy} {mode}", (policy, mode) in offered, str(offered))
    if a.expect_none:
        print(f"{r.passed} passed, {r.failed} failed")
        return 0 if r.failed == 0 else 1

    # An untrusted client certificate.
    cert, key = await make_cert(a.work, "client")
    rejected_before = set((a.pki / "rejected").iterdir())
    client = await secure_client(a.url, "Basic256Sha256", cert, key, a.user, a.password)
    try:
        await client.connect()
        await client.disconnect()
        r.check("an untrusted client certificate is refused", False, "the session opened")
    except Exception as e:  # noqa: BLE001
        r.check("an untrusted client certificate is refused", True)
        print("     refused with", status_name(e))
    new = sorted(set((a.pki / "rejected").iterdir()) - rejected_before)
    r.check("the refused certificate is in rejected/", len(new) == 1, str(new))
    # The administrator moves it to trusted/.
    for f in new:
        shutil.move(str(f), str(a.pki / "trusted" / f.name))

    # SignAndEncrypt with each policy and a user name (an Operator): read, write, call.
    for policy in POLICIES:
        client = await secure_client(a.url, policy, cert, key, a.user, a.password)
        try:
            await client.connect()
        except Exception as e:  # noqa: BLE001
            r.check(f"{policy} SignAndEncrypt as {a.user}", False, status_name(e))
            continue
        try:
            r.check(f"{policy} SignAndEncrypt as {a.user}", True)
            speed, obj, start = await demo_nodes(client)
            value = await client.get_node(speed).read_value()
            r.check(f"{policy}: read Speed", isinstance(value, float), repr(value))
            r.check(f"{policy}: Operator writes Speed", await write_status(client, speed, 21.0) == "Good")
            r.check(f"{policy}: Operator calls Start", await call_status(client, obj, start) == "Good")
        finally:
            await client.disconnect()

    # A wrong password.
    client = await secure_client(a.url, "Basic256Sha256", cert, key, a.user, a.password + "x")
    try:
        await client.connect()
        await client.disconnect()
        r.check("a wrong password is refused", False, "the session opened")
    except Exception as e:  # noqa: BLE001
        r.check("a wrong password is refused", "BadIdentityTokenRejected" in status_name(e) or "BadUserAccessDenied" in status_name(e), status_name(e))

    # Anonymous: read yes, write and call no.
    client = await secure_client(a.url, "Basic256Sha256", cert, key)
    await client.connect()
    try:
        speed, obj, start = await demo_nodes(client)
        value = await client.get_node(speed).read_value()
        r.check("anonymous reads Speed", isinstance(value, float), repr(value))
        r.check("anonymous write is refused with BadUserAccessDenied", (s := await write_status(client, speed, 22.0)) == "BadUserAccessDenied", s)
        r.check("anonymous call is refused with BadUserAccessDenied", (s := await call_status(client, obj, start)) == "BadUserAccessDenied", s)
        level = (await client.get_node(speed).read_attribute(ua.AttributeIds.UserAccessLevel)).Value.Value
        r.check("anonymous UserAccessLevel of Speed is CurrentRead only", level == 1, repr(level))
        executable = (await client.get_node(start).read_attribute(ua.AttributeIds.UserExecutable)).Value.Value
        r.check("anonymous UserExecutable of Start is false", executable is False, repr(executable))
    finally:
        await client.disconnect()

    # An Observer: authenticated, but not an Operator.
    client = await secure_client(a.url, "Aes256_Sha256_RsaPss", cert, key, a.observer, a.observer_password)
    await client.connect()
    try:
        speed, obj, start = await demo_nodes(client)
        r.check("Observer write is refused with BadUserAccessDenied", (s := await write_status(client, speed, 23.0)) == "BadUserAccessDenied", s)
        r.check("Observer call is refused with BadUserAccessDenied", (s := await call_status(client, obj, start)) == "BadUserAccessDenied", s)
    finally:
        await client.disconnect()

    print(f"{r.passed} passed, {r.failed} failed")
    return 0 if r.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
