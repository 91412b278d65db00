"""Structure values read back with python asyncua (a third-party client), field by field.

Run against `structures_server` (tests/rust-fixtures/examples), which serves the `structure_values` fixture:

    structures_check.py --url URL --fixture tests/fixtures/structure_values

The expectations come from the fixture's XML, parsed here independently of nodeset-compiler. For every variable
of the fixture's own namespace whose `<Value>` is an ExtensionObject (or a list of them), the value asyncua
reads (after `load_data_type_definitions`, which builds its classes from the DataTypeDefinitions the server
serves; ns0's EUInformation and Range are asyncua's own) must hold, for each field of its class:
- the field's element of the XML body, compared by kind: numbers, strings, booleans, enumerations written
  `Name_5`, LocalizedText (Locale, Text), NodeId and QualifiedName (the file's namespace indices mapped to the
  server's by URI), a Variant (`<Value>`), arrays item by item, nested structures (in place, or as an
  ExtensionObject with TypeId and Body) recursively;
- null (None, 0, an empty string, a structure whose fields are null) where the XML leaves the field out;
  for a union, the SwitchField and the one field it selects (asyncua's `Encoding` and `Value`).

It prints one line per check (report.py) and ends with `N passed, M failed`.
"""

import argparse
import asyncio
import dataclasses
import enum
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from asyncua import Client, ua

from report import Report

NS = "{http://opcfoundation.org/UA/2011/03/UANodeSet.xsd}"
TYPES = "{http://opcfoundation.org/UA/2008/02/Types.xsd}"


def local(tag: str) -> str:
    return tag.split("}", 1)[-1]


def child(el, name: str):
    for c in el:
        if local(c.tag) == name:
            return c
    return None


class Fixture:
    """The namespace URIs and aliases of the fixture's main file, and its structure values."""

    def __init__(self, folder: Path):
        main = next(p for p in sorted(folder.glob("*.xml")) if "Parts" not in p.name)
        root = ET.parse(main).getroot()
        self.uris = [u.text for u in root.findall(f"{NS}NamespaceUris/{NS}Uri")]
        self.aliases = {a.get("Alias"): a.text.strip() for a in root.findall(f"{NS}Aliases/{NS}Alias")}
        self.values = []
        for el in root.findall(f"{NS}UAVariable"):
            value = el.find(f"{NS}Value")
            if value is None or len(value) == 0:
                continue
            v = value[0]
            if local(v.tag) not in ("ExtensionObject", "ListOfExtensionObject"):
                continue
            ident = int(el.get("NodeId").split("i=", 1)[1])
            self.values.append((el.get("BrowseName").split(":", 1)[1], ident, v))

    def uri_of(self, file_index: int) -> str:
        return "http://opcfoundation.org/UA/" if file_index == 0 else self.uris[file_index - 1]


class Compare:
    def __init__(self, fixture: Fixture, server_uris: list[str]):
        self.fx = fixture
        self.server_uris = server_uris
        self.problems: list[str] = []
        self.fields = 0

    def server_ns(self, file_index: int) -> int:
        return self.server_uris.index(self.fx.uri_of(file_index))

    def node_id(self, text: str):
        text = self.fx.aliases.get(text.strip(), text.strip())
        ns = 0
        if text.startswith("ns="):
            head, text = text.split(";", 1)
            ns = int(head[3:])
        kind, ident = text.split("=", 1)
        assert kind == "i", f"the fixture uses numeric NodeIds only, not {text}"
        return ua.NodeId(int(ident), self.server_ns(ns))

    def fail(self, path: str, message: str):
        self.problems.append(f"{path}: {message}")

    def is_null(self, v) -> bool:
        if v is None or v == 0 or v == "" or v is False or v == []:
            return True
        if isinstance(v, ua.NodeId):
            return v.is_null()
        if isinstance(v, ua.QualifiedName):
            return v.NamespaceIndex == 0 and not v.Name
        if isinstance(v, ua.LocalizedText):
            return not v.Text and not v.Locale
        if isinstance(v, ua.Variant):
            return v.Value is None
        if dataclasses.is_dataclass(v):
            return all(self.is_null(getattr(v, f.name)) for f in dataclasses.fields(v) if f.name != "Encoding")
        return False

    def structure(self, body, obj, path: str):
        """A structure's XML body against asyncua's object, field by field."""
        if not dataclasses.is_dataclass(obj):
            self.fail(path, f"not decoded into a structure class: {obj!r}")
            return
        fields = [f.name for f in dataclasses.fields(obj) if f.name != "Encoding"]
        if isinstance(obj, ua.UaUnion):
            switch = child(body, "SwitchField")
            want = int(switch.text) if switch is not None else 0
            self.fields += 1
            if obj.Encoding != want:
                self.fail(path, f"SwitchField {obj.Encoding}, expected {want}")
                return
            # asyncua holds the selected field in `Value`; the XML names it after the SwitchField.
            given = [c for c in body if local(c.tag) != "SwitchField"]
            if want and len(given) == 1:
                self.value(given[0], obj.Value, f"{path}.{local(given[0].tag)}")
            elif want:
                self.fail(path, f"the nodeset's union gives {len(given)} fields")
            return
        xml_names = [local(c.tag) for c in body]
        for name in xml_names:
            if name not in fields:
                self.fail(path, f"the class has no field {name} (it has {fields})")
        for name in fields:
            el = child(body, name)
            got = getattr(obj, name)
            self.fields += 1
            if el is None:
                if not self.is_null(got):
                    self.fail(f"{path}.{name}", f"left out in the nodeset, but read as {got!r}")
            else:
                self.value(el, got, f"{path}.{name}")

    def value(self, el, got, path: str):
        if child(el, "TypeId") is not None and child(el, "Body") is not None:
            body = child(el, "Body")
            self.structure(body[0], got, path)
        elif isinstance(got, list):
            items = list(el)
            if len(items) != len(got):
                self.fail(path, f"{len(got)} items, expected {len(items)}")
                return
            for i, (x, g) in enumerate(zip(items, got)):
                self.value(x, g, f"{path}[{i}]")
        elif isinstance(got, ua.LocalizedText):
            locale, text = child(el, "Locale"), child(el, "Text")
            want = (locale.text if locale is not None else None, text.text if text is not None else None)
            if (got.Locale or None, got.Text or None) != want:
                self.fail(path, f"{got!r}, expected Locale/Text {want}")
        elif isinstance(got, ua.NodeId):
            want = self.node_id(child(el, "Identifier").text)
            if got != want:
                self.fail(path, f"{got.to_string()}, expected {want.to_string()}")
        elif isinstance(got, ua.QualifiedName):
            ns = child(el, "NamespaceIndex")
            want = ua.QualifiedName(child(el, "Name").text, self.server_ns(int(ns.text) if ns is not None else 0))
            if got != want:
                self.fail(path, f"{got!r}, expected {want!r}")
        elif isinstance(got, ua.Variant):
            inner = child(el, "Value")
            self.value(inner[0], got.Value, path)
        elif dataclasses.is_dataclass(got):
            self.structure(el, got, path)
        elif isinstance(got, enum.Enum):
            want = int(el.text.strip().rsplit("_", 1)[-1])
            if got.value != want:
                self.fail(path, f"{got!r}, expected {want}")
        elif isinstance(got, bool):
            if got != (el.text.strip() in ("true", "1")):
                self.fail(path, f"{got!r}, expected {el.text!r}")
        elif isinstance(got, int):
            if got != int(el.text.strip()):
                self.fail(path, f"{got!r}, expected {el.text!r}")
        elif isinstance(got, float):
            if got != float(el.text.strip()):
                self.fail(path, f"{got!r}, expected {el.text!r}")
        elif isinstance(got, str):
            if got != (el.text or ""):
                self.fail(path, f"{got!r}, expected {el.text!r}")
        else:
            self.fail(path, f"a value of an unexpected kind: {got!r}")


async def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--url", required=True)
    p.add_argument("--fixture", required=True, type=Path)
    args = p.parse_args()
    fx = Fixture(args.fixture)
    r = Report()
    async with Client(args.url) as client:
        await client.load_data_type_definitions()
        uris = await client.get_namespace_array()
        own = uris.index(fx.uris[0])
        kinds = {}
        for name, ident, xml in fx.values:
            cmp = Compare(fx, uris)
            got = await client.get_node(ua.NodeId(ident, own)).read_value()
            if local(xml.tag) == "ListOfExtensionObject":
                if not isinstance(got, list) or len(got) != len(xml):
                    cmp.fail(name, f"{got!r} is not a list of {len(xml)} structures")
                else:
                    for i, (x, g) in enumerate(zip(xml, got)):
                        cmp.value(x, g, f"{name}[{i}]")
            else:
                cmp.value(xml, got, name)
            kinds[name] = type(got[0] if isinstance(got, list) and got else got).__name__
            r.all(f"{name} read back as the nodeset's value, {cmp.fields} fields", cmp.problems, cmp.fields)
        r.equal("ns0's structures arrive as asyncua's own classes",
                (kinds.get("Unit"), kinds.get("Span"), kinds.get("Spans")), ("EUInformation", "Range", "Range"))
        r.check(f"{len(fx.values)} structure values checked", len(fx.values) >= 12, f"{len(fx.values)}")
    print(f"{r.passed} passed, {r.failed} failed")
    return 0 if r.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(asyncio.run(main()))
