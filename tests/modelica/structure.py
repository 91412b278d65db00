#!/usr/bin/env python3
"""Structural checks of a Modelica library that rumoca 0.10.2 does not make.

Usage:
    structure.py ROOT [--only PREFIX]... [--quiet]

Every class below ROOT (the folder check.py takes) is read with pymoca's parser (pymoca==0.12.0, the second
checker's front end) and checked for

* conditional reads: no equation, algorithm or binding (a declaration's `= expr` or a modifier's value) reads
  a component declared with a condition (`Part part if usePart`), its own or inherited; Modelica 4.4.5 lets
  such a component be modified and connected, nothing else (connect equations are allowed);
* modifier targets: every modifier names a member of the class it modifies, at every depth (`a(b(c=1))`, in
  a component's declaration, an `extends` clause and a short class definition), `redeclare model X = ...`
  names a class member and `redeclare T x` a component. A member's class is the one in effect in the class
  being checked: its own choice of each replaceable class, after the redeclarations of its `extends`
  clauses and of the modification itself. Attributes of the predefined types (start, unit, ...) are members.

Recursive classes are checked by the Rust test `no_generated_class_contains_itself`, which walks the class
graph (tests/tests/modelica.rs), and pymoca's flattening (check2.py) fails on them too. What needs an instance
tree (which choice of a replaceable class reaches a component through the classes that enclose it) is pymoca's
flattening's part (check2.py): this script judges each class on its own.

pymoca's parser keeps no condition attribute, so conditional components are found in the class's text (one
class per file, as the generator writes them; classes nested in a package.mo are checked for modifiers
only). --only PREFIX checks only the classes whose name starts with PREFIX (everything is still loaded).
The last line of the output is always `N passed, N failed`, counting classes.
"""

import os
import re
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check  # noqa: E402

PREDEFINED = {"Real", "Integer", "Boolean", "String", "StateSelect", "AssertionLevel", "ExternalObject", "Clock"}
# The attributes a modifier of a predefined type (or of a type, connector or enumeration built on one) names.
ATTRIBUTES = {"start", "fixed", "min", "max", "nominal", "unit", "quantity", "displayUnit", "stateSelect", "unbounded"}


class Library:
    """Every class below a root, by full name, parsed by pymoca."""

    def __init__(self, root):
        from pymoca import parser

        self.root = root
        tree = parser.modelicapath_to_tree([root])
        self.classes = {}
        # Classes whose file does not parse: {full name: message}.
        self.errors = {}
        stack = list(tree.classes.values())
        while stack:
            c = stack.pop()
            name = c.full_name
            try:
                children = list(c.classes.values())  # parses a lazily loaded class
            except Exception as e:  # ModelicaSyntaxError: not Modelica (rumoca may still accept it)
                self.errors[name] = " ".join(f"{type(e).__name__}: {e}".split())[:300]
                continue
            self.classes[name] = c
            stack.extend(children)
        self._members = {}

    def resolve(self, name, scope):
        """The class a type name means in `scope` (a class's full name), as the Modelica lookup finds it
        through the enclosing classes; None for a predefined type or a name that resolves to nothing."""
        parts = scope.split(".")
        first = name.split(".")[0]
        for i in range(len(parts), -1, -1):
            prefix = ".".join(parts[:i])
            if prefix in self.classes:
                # A member class of an enclosing class (or an inherited one: an alias of the scope).
                m = self.members(prefix).get(first)
                if m is not None and m[0] == "class":
                    rest = name.split(".")[1:]
                    target = m[1]
                    if not rest:
                        return target
                    if target is None:
                        return None
                    cand = target + "." + ".".join(rest)
                    return cand if cand in self.classes else None
            cand = (prefix + "." if prefix else "") + name
            if cand in self.classes and cand not in PREDEFINED:  # pymoca's tree holds the predefined types
                return cand
        return None

    def predefined(self, name, scope):
        return name in PREDEFINED and self.resolve(name, scope) is None

    def members(self, cname):
        """{name: ("comp", type name, declaring class) | ("class", full name of the class in effect or None)}
        of class `cname`, inherited ones included, with its own choices of replaceable classes; plus
        ("attr",) for the attributes when it is built on a predefined type."""
        if cname in self._members:
            return self._members[cname]
        self._members[cname] = {}  # a class that extends itself ends here
        c = self.classes[cname]
        out = {}
        for e in c.extends:
            base_name = str(e.component)
            if self.predefined(base_name, cname) or getattr(c, "enumeration", False):
                for a in ATTRIBUTES:
                    out[a] = ("attr",)
                continue
            base = self.resolve(base_name, parent_of(cname))
            if base is None:
                continue
            inherited = dict(self.members(base))
            for arg in e.class_modification.arguments if e.class_modification else []:
                if arg.redeclare and type(arg.value).__name__ == "ShortClassDefinition":
                    inherited[arg.value.name] = ("class", self.resolve(str(arg.value.component), cname))
            out.update(inherited)
        if getattr(c, "enumeration", False):
            for a in ATTRIBUTES:
                out[a] = ("attr",)
        for n, sub in c.classes.items():
            target = sub.full_name
            if sub.is_short_class_definition and sub.extends:
                b = str(sub.extends[0].component)
                target = None if self.predefined(b, cname) else self.resolve(b, cname)
            out[n] = ("class", target)
        for n, s in c.symbols.items():
            out[n] = ("comp", str(s.type), cname)
        self._members[cname] = out
        return out

    def component_class(self, member, redeclared, cname):
        """The class of component `member` (a members() entry) seen from class `cname`, with `redeclared`
        ({alias: class}) applied; "predefined" for a predefined type, None when it does not resolve."""
        _, tname, declared_in = member
        first = tname.split(".")[0]
        if first in redeclared and "." not in tname:
            return redeclared[first]
        if "." not in tname:
            m = self.members(cname).get(tname)
            if m is not None and m[0] == "class":
                return m[1] if m[1] is not None else "predefined"
        if self.predefined(tname, declared_in):
            return "predefined"
        return self.resolve(tname, declared_in)


def parent_of(name):
    return name.rsplit(".", 1)[0] if "." in name else ""


def kind(node):
    return type(node).__name__


def check_modification(lib, cm, target, where, problems, top=False):
    """Checks that every argument of modification `cm` names a member of class `target` (a full name,
    "predefined", or None when unknown)."""
    if cm is None or target is None:
        return
    members = {a: ("attr",) for a in ATTRIBUTES} if target == "predefined" else lib.members(target)
    redeclared = {}
    for arg in cm.arguments:
        v = arg.value
        if kind(v) == "ShortClassDefinition":
            m = members.get(v.name)
            if m is None or m[0] != "class":
                problems.append(f"{where}: `redeclare {v.type} {v.name}` names no class of {target}")
            else:
                redeclared[v.name] = lib.resolve(str(v.component), where.split(" ")[0])
    for arg in cm.arguments:
        v = arg.value
        if kind(v) == "ComponentClause":
            for s in v.symbol_list:
                m = members.get(s.name)
                if m is None or m[0] != "comp":
                    problems.append(f"{where}: `redeclare {v.type} {s.name}` names no component of {target}")
        elif kind(v) == "ElementModification":
            names = list(v.component.to_tuple())
            if top and names == ["value"] and not any(kind(x) == "ClassModification" for x in v.modifications):
                continue  # pymoca's form of a declaration's binding (`= expr`)
            cls = target
            path = []
            for i, n in enumerate(names):
                path.append(n)
                ms = {a: ("attr",) for a in ATTRIBUTES} if cls == "predefined" else lib.members(cls)
                m = ms.get(n)
                if m is None:
                    problems.append(f"{where}: modifier `{'.'.join(path)}` names no member of {cls}")
                    cls = None
                    break
                if m[0] == "comp":
                    cls = lib.component_class(m, redeclared if i == 0 else {}, cls)
                else:
                    cls = "predefined" if m[0] == "attr" else None
                if cls is None:
                    break
            if cls is None:
                continue
            for sub in v.modifications:
                if kind(sub) == "ClassModification":
                    check_modification(lib, sub, cls, f"{where} {'.'.join(names)}", problems)


def check_modifiers(lib, cname, c, problems):
    """Checks the modifications of class `c` (full name `cname`): its extends clauses' and its components'."""
    for e in c.extends:
        base_name = str(e.component)
        if lib.predefined(base_name, cname):
            target = "predefined"
        else:
            target = lib.resolve(base_name, parent_of(cname))
            if target is None:
                problems.append(f"{cname}: extends {base_name}, which does not resolve")
        check_modification(lib, e.class_modification, target, f"{cname} extends {base_name}", problems)
    for n, s in c.symbols.items():
        tname = str(s.type)
        target = lib.component_class(("comp", tname, cname), {}, cname)
        if target is None:
            problems.append(f"{cname}.{n}: its class {tname} does not resolve")
        check_modification(lib, s.class_modification, target, f"{cname}.{n}", problems, top=True)


def conditional_components(path):
    """Names of the components a class file declares with a condition attribute."""
    with open(path, encoding="utf-8") as fh:
        text = code_only(fh.read())
    out = set()
    for stmt in statements(text):
        words = stmt.split()
        if not words or words[0] in ("equation", "algorithm", "initial", "end", "annotation", "extends", "within"):
            if words and words[0] in ("equation", "algorithm", "initial"):
                break
            continue
        depth0 = depth_zero(stmt)
        toks = re.findall(r"[A-Za-z_][A-Za-z0-9_]*", depth0)
        n_if, n_then, n_elseif = toks.count("if"), toks.count("then"), toks.count("elseif")
        if n_if > n_then - n_elseif:
            head = re.split(r"[(\[=]|\bif\b", depth0, maxsplit=1)[0].split()
            if head:
                out.add(head[-1])
    return out


def code_only(text):
    """Comments removed, string contents emptied."""
    out = []
    i = 0
    while i < len(text):
        c = text[i]
        if c == '"':
            j = i + 1
            while j < len(text) and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""')
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = len(text) if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i)
            i = len(text) if j < 0 else j + 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


def statements(text):
    """The text split at each `;` outside brackets; the class header's statement starts the list."""
    out, cur, depth = [], [], 0
    for c in text:
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        if c == ";" and depth == 0:
            out.append("".join(cur))
            cur = []
        else:
            cur.append(c)
    return out


def depth_zero(stmt):
    out, depth = [], 0
    for c in stmt:
        if c in "([{":
            depth += 1
            out.append(" ")
        elif c in ")]}":
            depth -= 1
            out.append(" ")
        elif depth == 0:
            out.append(c)
    return "".join(out)


def refs(node, skip_connect=True):
    """The component references an expression, equation or statement reads (connect equations left out)."""
    from pymoca import ast

    if isinstance(node, list):
        for x in node:
            yield from refs(x, skip_connect)
        return
    if not isinstance(node, ast.Node):
        return
    if isinstance(node, ast.ConnectClause) and skip_connect:
        return
    if isinstance(node, ast.ComponentRef):
        yield node
        for idx in node.indices:
            yield from refs(idx, skip_connect)
        for ch in node.child:
            for idx in ch.indices:
                yield from refs(idx, skip_connect)
        return
    if isinstance(node, ast.Expression):
        # The operator of a function call is a function's name, not a read.
        yield from refs(node.operands, skip_connect)
        return
    for k, v in vars(node).items():
        if k in ("parent", "scope", "comment", "type"):
            continue
        yield from refs(v, skip_connect)


def modification_values(cm):
    """The expressions a modification binds (its values, not its targets), at every depth."""
    if cm is None:
        return
    for arg in cm.arguments:
        v = arg.value
        if kind(v) == "ElementModification":
            for x in v.modifications:
                if kind(x) == "ClassModification":
                    yield from modification_values(x)
                else:
                    yield x
        elif kind(v) == "ShortClassDefinition":
            yield from modification_values(v.class_modification)
        elif kind(v) == "ComponentClause":
            for s in v.symbol_list:
                yield from modification_values(s.class_modification)


def main(argv):
    pymoca = check.pymoca_or_none()
    opts = check.options(argv, __doc__) if pymoca else None
    if opts is None:
        return 2
    root, quiet, _, only = opts
    t0 = time.time()
    lib = Library(root)
    # Conditional components of each class file, by class name.
    files = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for f in filenames:
            if f.endswith(".mo") and f != "package.mo":
                rel = os.path.relpath(os.path.join(dirpath, f), root)[: -len(".mo")]
                files[rel.replace(os.sep, ".")] = os.path.join(dirpath, f)
    own_conditional = {name: conditional_components(p) for name, p in files.items()}

    def conditional(cname, seen=()):
        if cname in seen or cname not in lib.classes:
            return set()
        out = set(own_conditional.get(cname, ()))
        for e in lib.classes[cname].extends:
            base = lib.resolve(str(e.component), parent_of(cname))
            if base is not None:
                out |= conditional(base, seen + (cname,))
        return out

    names = sorted(n for n in lib.classes if n in files)
    if only:
        names = [n for n in names if any(n == p or n.startswith(p + ".") for p in only)]
    passed = 0
    failed = {}
    for cname, msg in sorted(lib.errors.items()):
        if cname in files and (not only or any(cname == p or cname.startswith(p + ".") for p in only)):
            failed[cname] = f"pymoca cannot parse it: {msg}"
            if not quiet:
                print(f"FAIL {cname}: {failed[cname]}", flush=True)
    for cname in names:
        problems = []
        # Modifier targets, in the class and in the classes it declares (replaceable aliases, ...).
        nested = [lib.classes[cname]]
        for c in nested:
            nested.extend(c.classes.values())
        for c in nested:
            check_modifiers(lib, c.full_name, c, problems)
        c = lib.classes[cname]
        # Conditional reads.
        cond = conditional(cname)
        if cond:
            reads = []
            for section in (c.equations, c.initial_equations, c.statements, c.initial_statements):
                reads.extend(("an equation", r) for r in refs(section))
            for e in c.extends:
                reads.extend((f"the modification of extends {e.component}", r) for x in modification_values(e.class_modification) for r in refs(x))
            for n, s in c.symbols.items():
                reads.extend((f"the declaration of {n}", r) for x in modification_values(s.class_modification) for r in refs(x))
            for where, r in reads:
                if r.name in cond:
                    problems.append(f"{cname}: {where} reads `{r}`, a conditional component (only connect and modify it)")
        if problems:
            failed[cname] = "; ".join(sorted(set(problems)))
            if not quiet:
                print(f"FAIL {cname}: {failed[cname]}", flush=True)
        else:
            passed += 1
            if not quiet:
                print(f"ok   {cname}", flush=True)
    checked = len(names) + sum(n in lib.errors for n in failed)
    what = f"structure (pymoca {pymoca.__version__} parser): checked {checked} classes below {root} in {time.time() - t0:.1f} s"
    return check.report(what, passed, failed, quiet)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
