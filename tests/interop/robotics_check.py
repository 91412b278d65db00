"""Interoperability check: a real third-party OPC UA client (python asyncua) against our server.

usage: .venv/bin/python tests/interop/robotics_check.py --url opc.tcp://127.0.0.1:4855/ \
           [--suite demo] [--suite robotics] [--nodesets nodesets/vendor]

Suites:

* ``demo``: the runtime's demo namespace (``cargo run -p nodeset-examples --example server -- --demo``):
  browsing, attributes, references in both directions, DataTypeDefinitions decoded with
  ``load_data_type_definitions``, writes and method calls with their status codes, a subscription.
* ``robotics``: the generated DI, IA and Robotics namespaces, checked against the NodeSet2 files
  themselves (parsed here, independently of nodeset-compiler): the NodeClass, BrowseName, DataType and
  ValueRank of every Robotics node, the supertype of every type, the instance declarations of
  MotionDeviceSystemType (recursively), every reference of every DI, IA and Robotics node in both
  directions, and the data types as ``load_data_type_definitions`` builds them from the server.

Every check prints PASS or FAIL; the last line is ``N passed, N failed``; the exit status is 1 if any
check failed. A suite that is asked for but cannot run (its namespace is missing, it crashes) fails.
"""

from __future__ import annotations

import argparse
import asyncio
import datetime
import logging
import sys
import traceback
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from asyncua import Client, ua

from report import Report

UA_NS = "http://opcfoundation.org/UA/"
DI_NS = "http://opcfoundation.org/UA/DI/"
IA_NS = "http://opcfoundation.org/UA/IA/"
ROBOTICS_NS = "http://opcfoundation.org/UA/Robotics/"
DEMO_NS = "urn:nodeset-models:demo"
XSD = "{http://opcfoundation.org/UA/2011/03/UANodeSet.xsd}"

# asyncua warns about every ns0 enumeration it meets twice while loading definitions; that is noise here.
logging.basicConfig(level=logging.ERROR)


def status_of(exc: Exception) -> str:
    code = getattr(exc, "code", None)
    if code is None:
        return repr(exc)
    try:
        return ua.StatusCode(code).name
    except Exception:
        return hex(code)


async def expect_status(report: Report, name: str, coro, expected: str) -> None:
    try:
        await coro
    except ua.UaStatusCodeError as e:
        report.equal(name, status_of(e), expected)
        return
    report.check(name, expected == "Good", f"no error, expected {expected}")


async def call_raw(client: Client, obj: ua.NodeId, method: ua.NodeId, args: list[ua.Variant]) -> ua.CallMethodResult:
    """Calls a method and returns the whole CallMethodResult (asyncua's Node.call_method hides the
    per-argument results)."""
    req = ua.CallMethodRequest()
    req.ObjectId = obj
    req.MethodId = method
    req.InputArguments = args
    return (await client.uaclient.call([req]))[0]


def code_name(code: ua.StatusCode) -> str:
    return ua.StatusCode(code.value).name


# ------------------------------------------------------------------------------------------ common


async def check_common(client: Client, report: Report) -> list[str]:
    ns_array = await client.get_namespace_array()
    print("NamespaceArray:", ns_array)
    report.equal("NamespaceArray[0] is the OPC UA namespace", ns_array[0] if ns_array else None, UA_NS)
    report.check("NamespaceArray has no empty entries", all(ns_array), repr(ns_array))
    report.equal("NamespaceArray has no duplicates", len(set(ns_array)), len(ns_array))
    return ns_array


# ------------------------------------------------------------------------------------------ demo


async def check_demo(client: Client, report: Report, ns_array: list[str], args) -> None:
    if not report.check("the demo namespace is served", DEMO_NS in ns_array, "start the server with --demo"):
        return
    ns = ns_array.index(DEMO_NS)

    def nid(i: int) -> ua.NodeId:
        return ua.NodeId(i, ns)

    # Browse the Objects folder.
    children = {(await c.read_browse_name()).to_string(): c for c in await client.nodes.objects.get_children()}
    report.check("Objects organizes Pump1 and Pump2", {f"{ns}:Pump1", f"{ns}:Pump2"} <= set(children), str(sorted(children)))
    pump1 = client.get_node(nid(5000))
    report.equal("Pump1 NodeClass", await pump1.read_node_class(), ua.NodeClass.Object)
    report.equal("Pump1 DisplayName", (await pump1.read_display_name()).Text, "Pump1")
    report.equal("Pump1 Description", (await pump1.read_description()).Text, "The first pump.")
    report.equal("Pump1 TypeDefinition is PumpType", await pump1.read_type_definition(), nid(2000))
    comps = {(await c.read_browse_name()).Name for c in await pump1.get_children()}
    expected = {"Speed", "Mode", "Position", "Counter", "Tags", "Empty", "Limit", "Start", "Move", "Disabled", "Stamp", "OperatorOnly", "Name"}
    report.check("Pump1 components", expected <= comps, str(sorted(comps)))

    # Attributes of variables.
    speed = client.get_node(nid(5001))
    report.equal("Speed DataType", await speed.read_data_type(), ua.NodeId(ua.ObjectIds.Double))
    report.equal("Speed ValueRank", await speed.read_value_rank(), -1)
    report.equal("Speed AccessLevel", (await speed.read_attribute(ua.AttributeIds.AccessLevel)).Value.Value, 3)
    report.equal("Speed MinimumSamplingInterval", (await speed.read_attribute(ua.AttributeIds.MinimumSamplingInterval)).Value.Value, 100.0)
    report.equal("Speed TypeDefinition is SpeedType", await speed.read_type_definition(), nid(2010))
    report.equal("Speed value", await speed.read_value(), 12.5)
    tags = client.get_node(nid(5005))
    report.equal("Tags ValueRank", await tags.read_value_rank(), 1)
    report.equal("Tags ArrayDimensions", await tags.read_array_dimensions(), [0])
    report.equal("Tags value", await tags.read_value(), ["wet", "loud"])
    empty = (await client.get_node(nid(5006)).read_data_value()).Value
    report.equal("Empty is an empty Int32 array", (empty.Value, empty.VariantType), ([], ua.VariantType.Int32))
    stamp = await client.get_node(nid(5015)).read_value()
    report.equal("Stamp DateTime", stamp.replace(tzinfo=None), datetime.datetime(2024, 1, 2, 3, 4, 5))
    name = await client.get_node(nid(5017)).read_value()
    report.equal("Name LocalizedText", (name.Locale, name.Text), ("en", "Feed pump"))
    report.equal("Mode DataType is DemoMode", await client.get_node(nid(5002)).read_data_type(), nid(1010))

    # References, forward and inverse, and the type hierarchy as seen from ns0.
    feeds = await pump1.get_references(refs=nid(1030), direction=ua.BrowseDirection.Forward)
    report.equal("Pump1 FeedsInto Pump2", [r.NodeId for r in feeds], [nid(5100)])
    fed = await client.get_node(nid(5100)).get_references(refs=nid(1030), direction=ua.BrowseDirection.Inverse)
    report.equal("Pump2 is FedFrom Pump1 (inverse)", [r.NodeId for r in fed], [nid(5000)])
    inverse_name = (await client.get_node(nid(1030)).read_attribute(ua.AttributeIds.InverseName)).Value.Value
    report.equal("FeedsInto InverseName", inverse_name.Text, "FedFrom")
    for base, sub, label in [
        (ua.ObjectIds.BaseObjectType, 2000, "PumpType"),
        (ua.ObjectIds.BaseDataVariableType, 2010, "SpeedType"),
        (ua.ObjectIds.Structure, 1000, "DemoPoint"),
        (ua.ObjectIds.Enumeration, 1010, "DemoMode"),
        (ua.ObjectIds.Double, 1020, "DemoSpeed"),
        (ua.ObjectIds.NonHierarchicalReferences, 1030, "FeedsInto"),
    ]:
        subs = [c.nodeid for c in await client.get_node(base).get_children(refs=ua.ObjectIds.HasSubtype)]
        report.check(f"{label} is a subtype of ns0 i={base} (browsed from ns0)", nid(sub) in subs)

    # DataTypeDefinitions and encodings.
    sdef = (await client.get_node(nid(1000)).read_attribute(ua.AttributeIds.DataTypeDefinition)).Value.Value
    report.equal("DemoPoint DefaultEncodingId", sdef.DefaultEncodingId, nid(1001))
    report.equal("DemoPoint BaseDataType", sdef.BaseDataType, ua.NodeId(ua.ObjectIds.Structure))
    report.equal("DemoPoint fields", [(f.Name, f.DataType) for f in sdef.Fields], [
        ("X", ua.NodeId(ua.ObjectIds.Double)), ("Y", ua.NodeId(ua.ObjectIds.Double)),
        ("Label", ua.NodeId(ua.ObjectIds.String)), ("Mode", nid(1010))])
    enc = await client.get_node(nid(1000)).get_references(refs=ua.ObjectIds.HasEncoding, direction=ua.BrowseDirection.Forward)
    report.equal("DemoPoint HasEncoding Default Binary", [(r.NodeId, r.BrowseName.to_string()) for r in enc], [(nid(1001), "0:Default Binary")])
    edef = (await client.get_node(nid(1010)).read_attribute(ua.AttributeIds.DataTypeDefinition)).Value.Value
    report.equal("DemoMode EnumDefinition", [(f.Name, f.Value) for f in edef.Fields], [("Off", 0), ("Slow", 5), ("Fast", 10)])
    enum_values = await client.get_node(nid(1011)).read_value()
    report.equal("DemoMode EnumValues", [(v.Value, v.DisplayName.Text) for v in enum_values], [(0, "Off"), (5, "Slow"), (10, "Fast")])
    inputs = await client.get_node(nid(5009)).read_value()
    report.equal("Start InputArguments", [(a.Name, a.DataType, a.ValueRank) for a in inputs],
                 [("Speed", ua.NodeId(ua.ObjectIds.Double), -1), ("Mode", nid(1010), -1)])

    # A structure value, decoded with the server's own definitions.
    await client.load_data_type_definitions()
    report.check("load_data_type_definitions builds DemoPoint and DemoMode", hasattr(ua, "DemoPoint") and hasattr(ua, "DemoMode"))
    position = await client.get_node(nid(5003)).read_value()
    report.check("Position decodes as DemoPoint", type(position).__name__ == "DemoPoint", repr(position))
    report.equal("Position value", (position.X, position.Y, position.Label, int(position.Mode)), (3.0, 4.0, "home", 10))

    # Writes.
    def dv(value, vtype):
        return ua.DataValue(ua.Variant(value, vtype))

    await expect_status(report, "write Double to Speed", speed.write_value(dv(42.0, ua.VariantType.Double)), "Good")
    report.equal("Speed after the write", await speed.read_value(), 42.0)
    await expect_status(report, "write out of range (the server's handler)", speed.write_value(dv(420.0, ua.VariantType.Double)), "BadOutOfRange")
    await expect_status(report, "write String to Speed", speed.write_value(dv("fast", ua.VariantType.String)), "BadTypeMismatch")
    await expect_status(report, "write Double[] to Speed", speed.write_value(dv([1.0], ua.VariantType.Double)), "BadTypeMismatch")
    counter = client.get_node(nid(5004))
    await expect_status(report, "write read-only Counter", counter.write_value(dv(1, ua.VariantType.Int32)), "BadNotWritable")
    await expect_status(report, "write OperatorOnly (UserAccessLevel read-only)",
                        client.get_node(nid(5016)).write_value(dv(1, ua.VariantType.Int32)), "BadUserAccessDenied")
    await expect_status(report, "write Int32 to the enumeration Mode", client.get_node(nid(5002)).write_value(dv(10, ua.VariantType.Int32)), "Good")
    await expect_status(report, "write Int64 to the enumeration Mode", client.get_node(nid(5002)).write_value(dv(10, ua.VariantType.Int64)), "BadTypeMismatch")
    await expect_status(report, "write Double to Limit (a subtype of Double)", client.get_node(nid(5007)).write_value(dv(80.0, ua.VariantType.Double)), "Good")
    await expect_status(report, "write String[] to Tags", tags.write_value(dv(["a", "b", "c"], ua.VariantType.String)), "Good")
    await expect_status(report, "write String to Tags", tags.write_value(dv("a", ua.VariantType.String)), "BadTypeMismatch")
    target = ua.DemoPoint(X=6.0, Y=8.0, Label="there", Mode=ua.DemoMode.Slow)
    await expect_status(report, "write DemoPoint to Position", client.get_node(nid(5003)).write_value(ua.DataValue(ua.Variant(target))), "Good")
    back = await client.get_node(nid(5003)).read_value()
    report.equal("Position after the write", (back.X, back.Y, back.Label, int(back.Mode)), (6.0, 8.0, "there", 5))
    await expect_status(report, "write Argument to Position", client.get_node(nid(5003)).write_value(ua.DataValue(ua.Variant(ua.Argument()))), "BadTypeMismatch")

    # Method calls.
    double, int32 = ua.VariantType.Double, ua.VariantType.Int32
    res = await call_raw(client, nid(5000), nid(5008), [ua.Variant(30.0, double), ua.Variant(10, int32)])
    report.equal("Start(30.0, Fast)", (code_name(res.StatusCode), [v.Value for v in res.OutputArguments or []]), ("Good", [True]))
    report.equal("Start set Speed", await speed.read_value(), 30.0)
    res = await call_raw(client, nid(5000), nid(5008), [ua.Variant(30.0, double)])
    report.equal("Start with one argument", code_name(res.StatusCode), "BadArgumentsMissing")
    res = await call_raw(client, nid(5000), nid(5008), [ua.Variant(1.0, double), ua.Variant(5, int32), ua.Variant(3, int32)])
    report.equal("Start with three arguments", code_name(res.StatusCode), "BadTooManyArguments")
    res = await call_raw(client, nid(5000), nid(5008), [ua.Variant("fast", ua.VariantType.String), ua.Variant(10, int32)])
    report.equal("Start with a String speed", (code_name(res.StatusCode), [code_name(s) for s in res.InputArgumentResults or []]),
                 ("BadInvalidArgument", ["BadTypeMismatch", "Good"]))
    res = await call_raw(client, nid(5000), nid(5008), [ua.Variant(1.0, double), ua.Variant(3, int32)])
    report.equal("Start with a Mode in a gap (the server's handler)", (code_name(res.StatusCode), [code_name(s) for s in res.InputArgumentResults or []]),
                 ("BadInvalidArgument", ["Good", "BadOutOfRange"]))
    res = await call_raw(client, nid(5000), nid(5011), [ua.Variant(ua.DemoPoint(X=6.0, Y=8.0, Label="far", Mode=ua.DemoMode.Off))])
    report.equal("Move(DemoPoint(6, 8))", (code_name(res.StatusCode), [v.Value for v in res.OutputArguments or []]), ("Good", [10.0]))
    res = await call_raw(client, nid(5000), nid(5014), [])
    # async-opcua refuses a method whose Executable is false with BadUserAccessDenied (not BadNotExecutable).
    report.equal("Disabled (Executable = false) is refused", code_name(res.StatusCode), "BadUserAccessDenied")

    # A subscription to the Counter the server's own code sets.
    class Handler:
        def __init__(self) -> None:
            self.values: list = []

        def datachange_notification(self, node, val, data) -> None:
            self.values.append(val)

    handler = Handler()
    sub = await client.create_subscription(100, handler)
    await sub.subscribe_data_change(counter)
    for _ in range(40):
        if len(set(handler.values)) >= 3:
            break
        await asyncio.sleep(0.1)
    await sub.delete()
    report.check("the Counter subscription sees the server's updates", len(set(handler.values)) >= 3, str(handler.values))


# ------------------------------------------------------------------------------------------ nodesets


@dataclass
class XNode:
    """A node as a NodeSet2 file declares it. Ids are (namespace URI, "i=123") pairs."""

    id: tuple
    node_class: str
    browse_name: tuple
    display_name: str
    data_type: tuple | None = None
    value_rank: int | None = None
    is_abstract: bool = False
    symmetric: bool = False
    inverse_name: str | None = None
    refs: list = field(default_factory=list)  # (reference type id, target id, is_forward)
    definition: list = field(default_factory=list)  # (name, value or None)
    is_option_set: bool = False


NODE_CLASSES = {
    "UAObject": ua.NodeClass.Object, "UAVariable": ua.NodeClass.Variable, "UAMethod": ua.NodeClass.Method,
    "UAObjectType": ua.NodeClass.ObjectType, "UAVariableType": ua.NodeClass.VariableType,
    "UADataType": ua.NodeClass.DataType, "UAReferenceType": ua.NodeClass.ReferenceType, "UAView": ua.NodeClass.View,
}


def parse_nodeset(path: Path, only_reference_types: bool = False) -> tuple[str, dict]:
    """The model URI and the nodes of a NodeSet2 file."""
    root = ET.parse(path).getroot()
    uris = [UA_NS] + [u.text for u in root.findall(f"{XSD}NamespaceUris/{XSD}Uri")]
    aliases = {a.get("Alias"): a.text for a in root.findall(f"{XSD}Aliases/{XSD}Alias")}
    model = root.find(f"{XSD}Models/{XSD}Model")
    model_uri = model.get("ModelUri") if model is not None else uris[-1]

    def key(text: str) -> tuple:
        text = aliases.get(text.strip(), text.strip())
        ns = 0
        if text.startswith("ns="):
            head, text = text.split(";", 1)
            ns = int(head[3:])
        return (uris[ns], text)

    def qname(text: str) -> tuple:
        if ":" in text and text.split(":", 1)[0].isdigit():
            ns, name = text.split(":", 1)
            return (uris[int(ns)], name)
        return (UA_NS, text)

    nodes = {}
    for el in root:
        tag = el.tag.replace(XSD, "")
        if tag not in NODE_CLASSES or (only_reference_types and tag != "UAReferenceType"):
            continue
        dn = el.find(f"{XSD}DisplayName")
        node = XNode(
            id=key(el.get("NodeId")),
            node_class=tag,
            browse_name=qname(el.get("BrowseName")),
            display_name=dn.text if dn is not None and dn.text else "",
            is_abstract=el.get("IsAbstract") == "true",
            symmetric=el.get("Symmetric") == "true",
        )
        if tag in ("UAVariable", "UAVariableType"):
            node.data_type = key(el.get("DataType", "i=24"))
            node.value_rank = int(el.get("ValueRank", "-1"))
        inv = el.find(f"{XSD}InverseName")
        node.inverse_name = inv.text if inv is not None else None
        for r in el.findall(f"{XSD}References/{XSD}Reference"):
            node.refs.append((key(r.get("ReferenceType")), key(r.text), r.get("IsForward", "true") != "false"))
        d = el.find(f"{XSD}Definition")
        if d is not None:
            node.is_option_set = d.get("IsOptionSet") == "true"
            for f in d.findall(f"{XSD}Field"):
                node.definition.append((f.get("Name"), f.get("Value")))
        nodes[node.id] = node
    return model_uri, nodes


HAS_TYPE_DEFINITION = (UA_NS, "i=40")
HAS_PROPERTY = (UA_NS, "i=46")
NAMESPACE_METADATA_TYPE = (UA_NS, "i=11616")


class Model:
    """DI, IA and Robotics from their NodeSet2 files, and the ns0 reference type hierarchy."""

    def __init__(self, folder: Path) -> None:
        self.files = {}
        self.nodes: dict = {}
        # Each file's NamespaceMetadata object (under Server/Namespaces) and its properties: the server folds
        # them into the object it keeps for every namespace it serves (defects_check.py checks that one).
        self.folded: set = set()
        self.folded_objects: list = []
        for name in ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"]:
            uri, nodes = parse_nodeset(folder / name)
            for k, x in list(nodes.items()):
                if (HAS_TYPE_DEFINITION, NAMESPACE_METADATA_TYPE, True) in x.refs:
                    self.folded_objects.append(k)
                    props = {t for (r, t, fwd) in x.refs if r == HAS_PROPERTY and fwd}
                    props |= {p for p, y in nodes.items() if (HAS_PROPERTY, k, False) in y.refs}
                    for gone in {k} | props:
                        self.folded.add(gone)
                        nodes.pop(gone, None)
            self.files[uri] = nodes
            self.nodes.update(nodes)
        _, ns0_refs = parse_nodeset(folder / "Opc.Ua.NodeSet2.xml", only_reference_types=True)
        self.reference_types = {**ns0_refs, **{k: v for k, v in self.nodes.items() if v.node_class == "UAReferenceType"}}
        # Every reference, declared in either direction, as (source, type, target), plus the nodes it touches.
        self.references: set = set()
        for node in self.nodes.values():
            for rtype, target, forward in node.refs:
                self.references.add((node.id, rtype, target) if forward else (target, rtype, node.id))

    def supertype(self, node: XNode):
        for rtype, target, forward in node.refs:
            if rtype == (UA_NS, "i=45") and not forward:
                return target
        for (s, rtype, t) in self.references:
            if rtype == (UA_NS, "i=45") and t == node.id:
                return s
        return None

    def is_subtype(self, rtype: tuple, ancestor: tuple) -> bool:
        seen = set()
        while rtype is not None and rtype not in seen:
            if rtype == ancestor:
                return True
            seen.add(rtype)
            node = self.reference_types.get(rtype)
            rtype = self.supertype(node) if node else None
        return False

    def is_subtype_of_type(self, dtype: tuple, ancestor: tuple) -> bool:
        seen = set()
        while dtype is not None and dtype not in seen:
            if dtype == ancestor:
                return True
            seen.add(dtype)
            node = self.nodes.get(dtype)
            dtype = self.supertype(node) if node else None
        return False


class Ids:
    """Converts between NodeSet (URI, "i=..") keys and the server's NodeIds."""

    def __init__(self, ns_array: list[str]) -> None:
        self.ns_array = ns_array

    def node_id(self, key: tuple) -> ua.NodeId:
        uri, text = key
        ns = self.ns_array.index(uri)
        kind, value = text.split("=", 1)
        if kind == "i":
            return ua.NodeId(int(value), ns)
        if kind == "s":
            return ua.NodeId(value, ns, ua.NodeIdType.String)
        if kind == "g":
            return ua.NodeId(ua.Guid(value), ns, ua.NodeIdType.Guid)
        return ua.NodeId(value.encode(), ns, ua.NodeIdType.ByteString)

    def key(self, node_id) -> tuple:
        if isinstance(node_id, ua.ExpandedNodeId) and node_id.NamespaceUri:
            uri = node_id.NamespaceUri
        else:
            uri = self.ns_array[node_id.NamespaceIndex] if node_id.NamespaceIndex < len(self.ns_array) else f"ns{node_id.NamespaceIndex}"
        t = node_id.NodeIdType
        if t in (ua.NodeIdType.TwoByte, ua.NodeIdType.FourByte, ua.NodeIdType.Numeric):
            return (uri, f"i={node_id.Identifier}")
        if t == ua.NodeIdType.String:
            return (uri, f"s={node_id.Identifier}")
        if t == ua.NodeIdType.Guid:
            return (uri, f"g={node_id.Identifier}")
        return (uri, f"b={node_id.Identifier}")

    def qname(self, q: ua.QualifiedName) -> tuple:
        return (self.ns_array[q.NamespaceIndex] if q.NamespaceIndex < len(self.ns_array) else f"ns{q.NamespaceIndex}", q.Name)


async def read_many(client: Client, ids: list[ua.NodeId], attr: ua.AttributeIds) -> list[ua.DataValue]:
    out = []
    for i in range(0, len(ids), 200):
        out += await client.uaclient.read_attributes(ids[i:i + 200], attr)
    return out


async def browse_all(client: Client, node_id: ua.NodeId, direction=ua.BrowseDirection.Both, refs=ua.ObjectIds.References) -> list:
    return await client.get_node(node_id).get_references(refs=refs, direction=direction, includesubtypes=True)


async def check_robotics(client: Client, report: Report, ns_array: list[str], args) -> None:
    missing = [u for u in (DI_NS, IA_NS, ROBOTICS_NS) if u not in ns_array]
    if not report.check("the DI, IA and Robotics namespaces are served", not missing, f"missing {missing}"):
        return
    model = Model(Path(args.nodesets))
    ids = Ids(ns_array)
    robotics = model.files[ROBOTICS_NS]

    # NodeClass, BrowseName, DisplayName of every Robotics node; DataType and ValueRank of its variables.
    keys = sorted(robotics)
    node_ids = [ids.node_id(k) for k in keys]
    classes = await read_many(client, node_ids, ua.AttributeIds.NodeClass)
    names = await read_many(client, node_ids, ua.AttributeIds.BrowseName)
    displays = await read_many(client, node_ids, ua.AttributeIds.DisplayName)
    problems = []
    for k, c, n, d in zip(keys, classes, names, displays):
        x = robotics[k]
        if not c.StatusCode.is_good():
            problems.append(f"{k}: {code_name(c.StatusCode)}")
            continue
        if ua.NodeClass(c.Value.Value) != NODE_CLASSES[x.node_class]:
            problems.append(f"{k}: NodeClass {ua.NodeClass(c.Value.Value).name}, expected {NODE_CLASSES[x.node_class].name}")
        if ids.qname(n.Value.Value) != x.browse_name:
            problems.append(f"{k}: BrowseName {n.Value.Value.to_string()}, expected {x.browse_name}")
        if d.Value.Value.Text != x.display_name:
            problems.append(f"{k}: DisplayName {d.Value.Value.Text!r}, expected {x.display_name!r}")
    report.check("one NamespaceMetadata object per file (DI, IA, Robotics) is left to the server's own",
                 sorted(u for (u, _) in model.folded_objects) == sorted([DI_NS, IA_NS, ROBOTICS_NS]),
                 f"objects {model.folded_objects}")
    report.all("NodeClass, BrowseName and DisplayName of every Robotics node", problems, len(keys))

    var_keys = [k for k in keys if robotics[k].data_type is not None]
    var_ids = [ids.node_id(k) for k in var_keys]
    dts = await read_many(client, var_ids, ua.AttributeIds.DataType)
    ranks = await read_many(client, var_ids, ua.AttributeIds.ValueRank)
    problems = []
    for k, dt, vr in zip(var_keys, dts, ranks):
        x = robotics[k]
        if not dt.StatusCode.is_good() or ids.key(dt.Value.Value) != x.data_type:
            problems.append(f"{k} {x.browse_name[1]}: DataType {dt.Value.Value if dt.Value else code_name(dt.StatusCode)}, expected {x.data_type}")
        if not vr.StatusCode.is_good() or vr.Value.Value != x.value_rank:
            problems.append(f"{k} {x.browse_name[1]}: ValueRank {vr.Value.Value if vr.Value else None}, expected {x.value_rank}")
    report.all("DataType and ValueRank of every Robotics variable and variable type", problems, len(var_keys))

    # The supertype of every type in DI, IA and Robotics (references into the namespaces below them).
    problems = []
    types = [x for x in model.nodes.values() if x.node_class in ("UAObjectType", "UAVariableType", "UADataType", "UAReferenceType")]
    for x in types:
        expected = model.supertype(x)
        refs = await browse_all(client, ids.node_id(x.id), ua.BrowseDirection.Inverse, ua.ObjectIds.HasSubtype)
        got = [ids.key(r.NodeId) for r in refs]
        if got != ([expected] if expected else []):
            problems.append(f"{x.browse_name[1]} {x.id}: supertype {got}, expected {expected}")
    report.all("the supertype of every DI, IA and Robotics type", problems, len(types))

    # MotionDeviceSystemType's instance declarations, recursively.
    mds = next(x for x in robotics.values() if x.browse_name == (ROBOTICS_NS, "MotionDeviceSystemType"))
    report.check("MotionDeviceSystemType is an ObjectType", mds.node_class == "UAObjectType")
    await check_instance_declarations(client, report, model, ids, mds)

    # Every reference of every DI, IA and Robotics node, in both directions.
    problems = []
    extra = []
    for uri in (DI_NS, IA_NS, ROBOTICS_NS):
        for k in sorted(model.files[uri]):
            expected = {(t, tgt, True) for (s, t, tgt) in model.references if s == k}
            expected |= {(t, src, False) for (src, t, tgt) in model.references if tgt == k}
            got = {(ids.key(r.ReferenceTypeId), ids.key(r.NodeId), r.IsForward) for r in await browse_all(client, ids.node_id(k))}
            for m in sorted(expected - got):
                problems.append(f"{k} {model.nodes[k].browse_name[1]}: missing {'forward' if m[2] else 'inverse'} {m[0]} -> {m[1]}")
            for e in sorted(got - expected):
                extra.append(f"{k}: {'forward' if e[2] else 'inverse'} {e[0]} -> {e[1]}")
    report.all("every declared reference of every DI, IA and Robotics node, both directions", problems, len(model.nodes))
    report.all("no references beyond the declared ones", extra, len(model.nodes))

    # Data types as a client builds them from the server's DataTypeDefinitions.
    loaded = await client.load_data_type_definitions()
    problems = []
    checked = 0
    for x in model.nodes.values():
        if x.node_class != "UADataType" or not x.definition:
            continue
        checked += 1
        name = x.browse_name[1]
        sdef = (await client.get_node(ids.node_id(x.id)).read_attribute(ua.AttributeIds.DataTypeDefinition)).Value.Value
        is_enum = model.is_subtype_of_type(x.id, (UA_NS, "i=29"))
        if is_enum or x.is_option_set:
            got = [(f.Name, f.Value) for f in getattr(sdef, "Fields", []) or []]
            want = [(n, int(v) if v is not None else i) for i, (n, v) in enumerate(x.definition)]
            if got != want:
                problems.append(f"{name}: EnumDefinition {got}, expected {want}")
            if is_enum:
                cls = loaded.get(name) or getattr(ua, name, None)
                members = sorted((m.name, int(m.value)) for m in cls) if cls else None
                if members != sorted(want):
                    problems.append(f"{name}: python enum {members}, expected {sorted(want)}")
        else:
            got = [f.Name for f in getattr(sdef, "Fields", []) or []]
            if got != [n for n, _ in x.definition]:
                problems.append(f"{name}: StructureDefinition fields {got}")
            if x.is_abstract:
                continue
            enc = await browse_all(client, ids.node_id(x.id), ua.BrowseDirection.Forward, ua.ObjectIds.HasEncoding)
            binary = [r.NodeId for r in enc if r.BrowseName.Name == "Default Binary"]
            if [ids.key(sdef.DefaultEncodingId)] != [ids.key(b) for b in binary]:
                problems.append(f"{name}: DefaultEncodingId {sdef.DefaultEncodingId}, Default Binary encodings {binary}")
            cls = loaded.get(name) or getattr(ua, name, None)
            if cls is None:
                problems.append(f"{name}: load_data_type_definitions built no class")
                continue
            # Round trip through the binary encoding with the ids the server announced.
            from asyncua.ua.ua_binary import extensionobject_from_binary, extensionobject_to_binary
            from asyncua.common.utils import Buffer
            value = cls()
            back = extensionobject_from_binary(Buffer(extensionobject_to_binary(value)))
            if type(back) is not cls:
                problems.append(f"{name}: a default value decodes as {type(back).__name__}")
    report.all("DataTypeDefinitions of DI, IA and Robotics decoded by load_data_type_definitions", problems, checked)

    # Values: the EnumStrings / EnumValues of the enumerations agree with their definitions.
    problems = []
    checked = 0
    for x in model.nodes.values():
        if x.node_class != "UADataType" or not x.definition or not model.is_subtype_of_type(x.id, (UA_NS, "i=29")):
            continue
        for r in await browse_all(client, ids.node_id(x.id), ua.BrowseDirection.Forward, ua.ObjectIds.HasProperty):
            checked += 1
            value = await client.get_node(r.NodeId).read_value()
            want = [(int(v) if v is not None else i, n) for i, (n, v) in enumerate(x.definition)]
            if r.BrowseName.Name == "EnumStrings":
                got = [(i, t.Text) for i, t in enumerate(value)]
            elif r.BrowseName.Name == "EnumValues":
                got = [(v.Value, v.DisplayName.Text) for v in value]
            else:
                continue
            if got != want:
                problems.append(f"{x.browse_name[1]}.{r.BrowseName.Name}: {got}, expected {want}")
    report.all("EnumStrings and EnumValues values of the enumerations", problems, checked)


HIERARCHICAL = (UA_NS, "i=33")
HAS_SUBTYPE = (UA_NS, "i=45")
HAS_TYPE_DEFINITION = (UA_NS, "i=40")
HAS_MODELLING_RULE = (UA_NS, "i=37")


async def check_instance_declarations(client: Client, report: Report, model: Model, ids: Ids, root: XNode) -> None:
    """Compares the hierarchical children of a type, recursively, with the NodeSet."""
    problems = []
    checked = 0
    queue = [(root, root.browse_name[1])]
    seen = {root.id}
    while queue:
        node, path = queue.pop(0)
        expected = {}
        for (s, t, tgt) in model.references:
            if s == node.id and t != HAS_SUBTYPE and model.is_subtype(t, HIERARCHICAL) and tgt in model.nodes:
                child = model.nodes[tgt]
                expected[child.browse_name] = (t, child)
        refs = await browse_all(client, ids.node_id(node.id), ua.BrowseDirection.Forward, ua.ObjectIds.HierarchicalReferences)
        got = {ids.qname(r.BrowseName): r for r in refs if ids.key(r.ReferenceTypeId) != HAS_SUBTYPE}
        if set(got) != set(expected):
            problems.append(f"{path}: children {sorted(n for _, n in got)}, expected {sorted(n for _, n in expected)}")
        for bn, (rtype, child) in sorted(expected.items()):
            r = got.get(bn)
            if r is None:
                continue
            checked += 1
            here = f"{path}/{bn[1]}"
            if ids.key(r.ReferenceTypeId) != rtype:
                problems.append(f"{here}: reference {ids.key(r.ReferenceTypeId)}, expected {rtype}")
            if r.NodeClass != NODE_CLASSES[child.node_class]:
                problems.append(f"{here}: NodeClass {r.NodeClass.name}, expected {child.node_class}")
            want_td = next((t for (rt, t, fwd) in child.refs if rt == HAS_TYPE_DEFINITION and fwd), None)
            got_td = ids.key(r.TypeDefinition) if r.TypeDefinition and not r.TypeDefinition.is_null() else None
            if child.node_class in ("UAObject", "UAVariable") and got_td != want_td:
                problems.append(f"{here}: TypeDefinition {got_td}, expected {want_td}")
            if child.data_type is not None:
                n = client.get_node(r.NodeId)
                if ids.key(await n.read_data_type()) != child.data_type:
                    problems.append(f"{here}: DataType {await n.read_data_type()}, expected {child.data_type}")
                if await n.read_value_rank() != child.value_rank:
                    problems.append(f"{here}: ValueRank {await n.read_value_rank()}, expected {child.value_rank}")
            want_rule = next((t for (rt, t, fwd) in child.refs if rt == HAS_MODELLING_RULE and fwd), None)
            rules = await browse_all(client, r.NodeId, ua.BrowseDirection.Forward, ua.ObjectIds.HasModellingRule)
            got_rule = ids.key(rules[0].NodeId) if rules else None
            if got_rule != want_rule:
                problems.append(f"{here}: ModellingRule {got_rule}, expected {want_rule}")
            if child.id not in seen and child.node_class not in ("UAObjectType", "UAVariableType", "UADataType", "UAReferenceType"):
                seen.add(child.id)
                queue.append((child, here))
    report.all(f"instance declarations of {root.browse_name[1]} (BrowseName, NodeClass, TypeDefinition, DataType, ValueRank, ModellingRule)", problems, checked)


# ------------------------------------------------------------------------------------------ main


SUITES = {"demo": check_demo, "robotics": check_robotics}


async def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", required=True)
    parser.add_argument("--suite", action="append", choices=sorted(SUITES), help="a suite to run (repeatable)")
    parser.add_argument("--nodesets", default=str(Path(__file__).resolve().parents[2] / "nodesets" / "vendor"),
                        help="folder of the pinned NodeSet2 files")
    args = parser.parse_args()
    report = Report()
    suites = args.suite or ["demo"]
    try:
        async with Client(url=args.url, timeout=30) as client:
            ns_array = await check_common(client, report)
            for name in suites:
                print(f"--- suite {name}", flush=True)
                try:
                    await SUITES[name](client, report, ns_array, args)
                except Exception:
                    traceback.print_exc()
                    report.check(f"suite {name} ran to the end", False, "it raised an exception")
    except Exception as e:
        traceback.print_exc()
        report.check(f"connect to {args.url}", False, repr(e))
    print(f"{report.passed} passed, {report.failed} failed", flush=True)
    return 1 if report.failed else 0


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
