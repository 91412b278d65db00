#!/usr/bin/env python3
"""Checks generated Modelica packages with pymoca, a second Modelica front end (pymoca==0.12.0 from PyPI).

Usage:
    check2.py ROOT [--only PREFIX]... [--jobs N] [--quiet]

The same classes and the same wrapper models as check.py (rumoca), compiled by an independent front end:
pymoca loads ROOT as its MODELICAPATH, instantiates the wrapper (`model Check__ extends <Class>; end
Check__;`, a record component, a zero-length array of a connector or type, a parameter per constant) and
flattens it. It fails on what rumoca 0.10.2 lets through (tests/modelica/planted holds one case of each):

* a modifier naming a member that does not exist, also nested (`a(b(c=1))`) and in an `extends` clause,
  judged on the class in effect after every redeclaration, outer modifications winning as Modelica 7.2.4
  says (rumoca checks only the top level of a component's modifiers);
* a class that contains itself (pymoca recurses without end: a RecursionError, reported as such).

pymoca does not flatten balanced equation systems the way rumoca does (a check is no simulation), and it
lets a read of a conditional component through; tests/modelica/structure.py checks that.

--only PREFIX checks only the classes whose name starts with PREFIX (the rest of ROOT is still loaded).
Each class is checked in a fresh tree; workers are separate processes, and a worker that dies marks its
class as failed. The last line of the output is always `N passed, N failed`.
"""

import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check  # noqa: E402  (the class list, the wrappers and the worker pool are rumoca's check's)

# pymoca's instantiation recurses once per nesting level and per extends; generated classes nest up to 64
# levels, which the default limit of 1000 frames does not always hold. A class that contains itself still
# ends in a RecursionError.
RECURSION_LIMIT = 20000


# pymoca 0.12 has no built-in ExternalObject (MLS 12.9.7): a class that extends it (OpcUaSupport.Live's server
# and client objects) fails name lookup. This stand-in, an empty partial class at the top level, lets pymoca
# flatten the classes that hold external objects; the constructor calls are flattened as function calls, not
# run (no Modelica tool here runs external C functions).
EXTERNAL_OBJECT = 'partial class ExternalObject "stand-in for the built-in class of MLS 12.9.7"\nend ExternalObject;\n'


def check_one(root, name, kind, partial, consts):
    from pymoca import ast, parser, tree

    src = check.wrapper(name, kind, partial, consts)
    if src is None:
        return False, f"cannot check a {kind} (no wrapper for this kind)"
    try:
        lib = parser.modelicapath_to_tree([root])
        lib.extend(parser.parse(src, bypass_cache=True))
        lib.extend(parser.parse(EXTERNAL_OBJECT, bypass_cache=True))
        tree.flatten(lib, ast.ComponentRef(name="Check__"))
        return True, ""
    except RecursionError:
        return False, "pymoca recursed without end: a class that contains itself?"
    except Exception as e:  # ModelicaSemanticError, NameLookupError, ModelicaSyntaxError, ...
        return False, " ".join(f"{type(e).__name__}: {e}".split())[:600]


def worker(root):
    """Runs in a child process: checks classes read from stdin, prints START/RESULT lines."""
    import threading

    sys.setrecursionlimit(RECURSION_LIMIT)
    threading.stack_size(512 * 1024 * 1024)

    def run():
        for line in sys.stdin:
            name, kind, partial, consts = check.decode(line.rstrip("\n"))
            print(f"START\t{name}", flush=True)
            ok, msg = check_one(root, name, kind, partial, consts)
            print(f"RESULT\t{name}\t{'OK' if ok else 'FAIL'}\t{msg}", flush=True)

    # A big recursion limit needs a big stack: run in a thread that has one.
    t = threading.Thread(target=run)
    t.start()
    t.join()


def main(argv):
    if len(argv) >= 2 and argv[0] == "--worker":
        worker(argv[1])
        return 0
    pymoca = check.pymoca_or_none()
    opts = check.options(argv, __doc__) if pymoca else None
    if opts is None:
        return 2
    root, quiet, jobs, only = opts
    items = check.classes(root)
    if only:
        items = [it for it in items if any(it[0] == p or it[0].startswith(p + ".") for p in only)]
    failed = {}
    for path, kind, *_ in items:
        if kind == "unknown":
            failed[path] = "no `within` clause or class header found"
    items = [it for it in items if it[1] != "unknown"]
    t0 = time.time()
    results = check.run_checks(root, items, jobs, quiet, script=os.path.abspath(__file__)) if items else {}
    passed = check.tally(results, failed)
    what = f"pymoca {pymoca.__version__}: checked {len(items)} classes below {root} in {time.time() - t0:.1f} s"
    return check.report(what, passed, failed, quiet)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
