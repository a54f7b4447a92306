"""`python -m protocol generate | check`: the RoverLink code generator."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from protocol.generator import generate, loader


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m protocol", description=__doc__)
    parser.add_argument(
        "command", choices=["generate", "check", "hash"], help="write outputs, verify them, or print the spec hash"
    )
    parser.add_argument("--spec", type=Path, default=generate.SPEC, help="spec file (default: %(default)s)")
    parser.add_argument("--root", type=Path, default=generate.ROOT, help="repository root the outputs live under")
    args = parser.parse_args(argv)
    try:
        spec, robot_list, contract = generate.load(args.spec, args.root)
    except loader.SpecError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    outputs = generate.render(spec, robot_list, contract) | generate.stamped(spec, args.root)
    if args.command == "hash":
        print(f"0x{spec.spec_hash:08X}")
        return 0
    if args.command == "generate":
        changed = generate.write(outputs, args.root)
        for rel in changed:
            print(f"wrote {rel}")
        print(f"{len(outputs)} files from {spec.path} (spec hash 0x{spec.spec_hash:08X}), {len(changed)} changed")
        return 0
    problems = generate.stale(outputs, args.root)
    for rel, diff in problems:
        print(f"stale: {rel}", file=sys.stderr)
        if diff != "missing":
            print(diff, file=sys.stderr)
        else:
            print("  (file is missing)", file=sys.stderr)
    if problems:
        print(
            f"{len(problems)} generated file(s) do not match {spec.path}: "
            "run `python -m protocol generate` and commit the result",
            file=sys.stderr,
        )
        return 1
    print(f"{len(outputs)} generated files match {spec.path} (spec hash 0x{spec.spec_hash:08X})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
