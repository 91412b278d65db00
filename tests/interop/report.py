"""The PASS/FAIL report every interop check script prints: one line per check, then ``N passed, N failed``,
which the Rust tests read."""

from __future__ import annotations


class Report:
    """Counts and prints checks."""

    def __init__(self) -> None:
        self.passed = 0
        self.failed = 0

    def check(self, name: str, ok: bool, detail: str = "") -> bool:
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        print(("PASS " if ok else "FAIL ") + name + (f"  [{detail}]" if detail and not ok else ""), flush=True)
        return ok

    def equal(self, name: str, got, expected) -> bool:
        return self.check(name, got == expected, f"got {got!r}, expected {expected!r}")

    def all(self, name: str, problems: list[str], total: int) -> bool:
        """One check over many items: passes if `problems` is empty; prints the first problems."""
        ok = self.check(f"{name} ({total} checked)", not problems, f"{len(problems)} wrong")
        for p in problems[:25]:
            print(f"     {p}")
        if len(problems) > 25:
            print(f"     ... and {len(problems) - 25} more")
        return ok
