"""RolePermissions obeyed node by node, checked with python asyncua (a third-party client).

Run against `roles_server` (tests/rust-fixtures/examples) started with `--trust-on-first-use --users FILE`:

    roles_check.py --url URL --nodeset tests/fixtures/roles/Example.Roles.NodeSet2.xml --work DIR --user NAME=ROLE:PASSWORD ...

The expectations come from the fixture itself, parsed here independently of nodeset-compiler: for every
variable and method of its namespace and every session (anonymous and each user, over SignAndEncrypt with
Basic256Sha256), the node's RolePermissions (or, where it has none, the server's documented default: every
role browses and reads, Operator, Engineer, Supervisor and ConfigureAdmin also write and call) decide
- a variable's UserAccessLevel (CurrentRead with Read, CurrentWrite with Write and the AccessLevel's
  CurrentWrite), whether reading its value works or is refused with BadUserAccessDenied, and whether a
  write is accepted or refused with BadUserAccessDenied;
- a method's UserExecutable (its attributes unreadable, BadUserAccessDenied, without Browse), and whether
  a call is accepted or refused with BadUserAccessDenied.

Then each user connects again over Basic256Sha256 with mode Sign: a variable whose AccessRestrictions
require encryption (bit 2) refuses a read, a write and a subscription of its value with
BadSecurityModeInsufficient, while the variables without restrictions answer as over SignAndEncrypt.

It prints one line per check (report.py) and ends with `N passed, M failed`.
"""

import argparse
import asyncio
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto import cert_gen, security_policies
from cryptography.x509.oid import ExtendedKeyUsageOID

from report import Report

XSD = "{http://opcfoundation.org/UA/2011/03/UANodeSet.xsd}"
APP_URI = "urn:nodeset-tests:roles-check"
BROWSE, READ, WRITE, CALL = 0x1, 0x20, 0x40, 0x1000
ROLES = {15644: "Anonymous", 15656: "AuthenticatedUser", 15668: "Observer", 15680: "Operator",
         16036: "Engineer", 15692: "Supervisor", 15716: "ConfigureAdmin", 15704: "SecurityAdmin"}
LOOK = 0x1 | READ | 0x800
DEFAULT = {r: (LOOK | WRITE | CALL) if r in ("Operator", "Engineer", "Supervisor", "ConfigureAdmin") else LOOK
           for r in ROLES.values()}


def fixture(path: Path):
    """The namespace URI and, per node of it, (BrowseName, class, AccessLevel, {role: permissions} or None)."""
    root = ET.parse(path).getroot()
    uri = root.find(f"{XSD}NamespaceUris/{XSD}Uri").text
    aliases = {a.get("Alias"): a.text for a in root.findall(f"{XSD}Aliases/{XSD}Alias")}
    nodes = {}
    for el in root:
        tag = el.tag.replace(XSD, "")
        if tag not in ("UAVariable", "UAMethod"):
            continue
        perms = None
        rp = el.find(f"{XSD}RolePermissions")
        if rp is not None:
            perms = {}
            for p in rp.findall(f"{XSD}RolePermission"):
                role = aliases.get(p.text.strip(), p.text.strip())
                name = ROLES[int(role.split("=", 1)[1])]
                perms[name] = perms.get(name, 0) | int(p.get("Permissions"))
        ident = int(el.get("NodeId").split("i=", 1)[1])
        nodes[ident] = (el.get("BrowseName").split(":", 1)[1], tag, int(el.get("AccessLevel", "1")), perms,
                        int(el.get("AccessRestrictions", "0")))
    return uri, nodes


def allowed(perms, roles: list[str]) -> int:
    table = DEFAULT if perms is None else perms
    bits = 0
    for r in roles:
        bits |= table.get(r, 0)
    return bits


def status_name(e: BaseException) -> str:
    if isinstance(e, ua.UaStatusCodeError):
        return ua.StatusCode(e.code).name
    return f"{type(e).__name__}: {e}"


async def session_checks(r: Report, client: Client, who: str, roles: list[str], uri: str, nodes: dict) -> None:
    ns = (await client.get_namespace_array()).index(uri)
    press = ua.NodeId(5001, ns)
    for ident, (name, tag, access_level, perms, _) in sorted(nodes.items()):
        node = client.get_node(ua.NodeId(ident, ns))
        bits = allowed(perms, roles)
        if tag == "UAVariable":
            want = (1 if bits & READ else 0) | (2 if bits & WRITE and access_level & 2 else 0)
            try:
                ual = (await node.read_attribute(ua.AttributeIds.UserAccessLevel)).Value.Value & 3
            except ua.UaStatusCodeError as e:
                # async-opcua refuses every attribute of a variable the session may not read.
                ual = status_name(e)
            expected = want if bits & READ else "BadUserAccessDenied"
            r.check(f"{who}: {name} UserAccessLevel", ual == expected, f"{ual}, expected {expected} (permissions {bits:#x})")
            try:
                value = await node.read_value()
                got = "Good"
            except Exception as e:  # noqa: BLE001 - the status is what is checked
                value, got = None, status_name(e)
            r.check(f"{who}: {name} read", got == ("Good" if bits & READ else "BadUserAccessDenied"), got)
            current = value if value is not None else {"Setpoint": 20.5, "Recipe": "steel-2mm", "Status": 0}[name]
            vtype = {float: ua.VariantType.Double, str: ua.VariantType.String, int: ua.VariantType.Int32}[type(current)]
            try:
                await node.write_value(ua.DataValue(ua.Variant(current, vtype)))
                got = "Good"
            except Exception as e:  # noqa: BLE001
                got = status_name(e)
            r.check(f"{who}: {name} write", got == ("Good" if bits & WRITE else "BadUserAccessDenied"), got)
        else:
            try:
                ue = (await node.read_attribute(ua.AttributeIds.UserExecutable)).Value.Value
            except ua.UaStatusCodeError as e:
                # A method the session may not browse: none of its attributes can be read.
                ue = status_name(e)
            expected = bool(bits & CALL) if bits & BROWSE else "BadUserAccessDenied"
            r.check(f"{who}: {name} UserExecutable", ue == expected, f"{ue}, expected {expected} (permissions {bits:#x})")
            req = ua.CallMethodRequest()
            req.ObjectId, req.MethodId, req.InputArguments = press, ua.NodeId(ident, ns), []
            got = ua.StatusCode((await client.uaclient.call([req]))[0].StatusCode.value).name
            r.check(f"{who}: {name} call", got == ("Good" if bits & CALL else "BadUserAccessDenied"), got)


ENCRYPTION_REQUIRED = 0x2


class NoNotifications:
    def datachange_notification(self, *args) -> None:
        pass


async def signed_only_checks(r: Report, client: Client, who: str, roles: list[str], uri: str, nodes: dict) -> int:
    """Over a signed but unencrypted channel: restricted values refused, the others as the roles allow.
    Returns how many restricted values the session could have read over SignAndEncrypt."""
    ns = (await client.get_namespace_array()).index(uri)
    restricted = 0
    for ident, (name, tag, _, perms, restrictions) in sorted(nodes.items()):
        if tag != "UAVariable" or not allowed(perms, roles) & READ:
            continue
        node = client.get_node(ua.NodeId(ident, ns))
        try:
            value = await node.read_value()
            got = "Good"
        except Exception as e:  # noqa: BLE001 - the status is what is checked
            value, got = None, status_name(e)
        if not restrictions & ENCRYPTION_REQUIRED:
            r.check(f"{who} (Sign): {name} read", got == "Good", got)
            continue
        restricted += 1
        r.check(f"{who} (Sign): {name} read refused (EncryptionRequired)", got == "BadSecurityModeInsufficient", got)
        try:
            await node.write_value(ua.DataValue(ua.Variant("steel-3mm", ua.VariantType.String)))
            got = "Good"
        except Exception as e:  # noqa: BLE001
            got = status_name(e)
        r.check(f"{who} (Sign): {name} write refused (EncryptionRequired)", got == "BadSecurityModeInsufficient", got)
        sub = await client.create_subscription(50, NoNotifications())
        try:
            await sub.subscribe_data_change(node)
            got = "Good"
        except Exception as e:  # noqa: BLE001
            got = status_name(e)
        r.check(f"{who} (Sign): {name} subscription refused (EncryptionRequired)", got == "BadSecurityModeInsufficient", got)
        await sub.delete()
    return restricted


async def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--url", required=True)
    p.add_argument("--nodeset", required=True, type=Path)
    p.add_argument("--work", required=True, type=Path)
    p.add_argument("--user", action="append", default=[], help="NAME=ROLE:PASSWORD (repeatable)")
    a = p.parse_args()
    a.work.mkdir(parents=True, exist_ok=True)
    uri, nodes = fixture(a.nodeset)
    r = Report()
    r.check("the fixture gives RolePermissions to some nodes and leaves others to the default",
            any(v[3] for v in nodes.values()) and any(v[3] is None for v in nodes.values()), str(nodes))
    r.check("the fixture requires encryption for some node", any(v[4] & ENCRYPTION_REQUIRED for v in nodes.values()), str(nodes))
    key, cert = a.work / "client.pem", a.work / "client.der"
    if not cert.exists():
        await cert_gen.setup_self_signed_certificate(
            key, cert, APP_URI, "localhost", [ExtendedKeyUsageOID.CLIENT_AUTH], {"commonName": "roles-check"})
    sessions = [("anonymous", ["Anonymous"], None, None)]
    for u in a.user:
        name, rest = u.split("=", 1)
        role, password = rest.split(":", 1)
        sessions.append((name, ["AuthenticatedUser", role], name, password))
    for who, roles, user, password in sessions:
        client = Client(a.url, timeout=10)
        client.application_uri = APP_URI
        if user is not None:
            client.set_user(user)
            client.set_password(password)
        await client.set_security(security_policies.SecurityPolicyBasic256Sha256, str(cert), str(key),
                                  mode=ua.MessageSecurityMode.SignAndEncrypt)
        async with client:
            await session_checks(r, client, who, roles, uri, nodes)
    restricted = 0
    for who, roles, user, password in sessions:
        if user is None:
            continue
        client = Client(a.url, timeout=10)
        client.application_uri = APP_URI
        client.set_user(user)
        client.set_password(password)
        await client.set_security(security_policies.SecurityPolicyBasic256Sha256, str(cert), str(key),
                                  mode=ua.MessageSecurityMode.Sign)
        async with client:
            restricted += await signed_only_checks(r, client, who, roles, uri, nodes)
    r.check("some user may read a variable that requires encryption (checked over Sign)", restricted > 0, "none")
    print(f"{r.passed} passed, {r.failed} failed")
    return 0 if r.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
