"""Codec throughput benchmark: RoverLink vs pymavlink (MAVLink 2) vs pySerialTransfer.

What is measured
----------------
For each stack, in one process on one machine, with the same payload size:

* **encode**: Python field values -> message object -> wire bytes, for N frames.
  - RoverLink: ``encode_frame(MsgClass(*values), seq)``.
  - pymavlink: ``MsgClass(*values).pack(mav)`` (MAVLink 2, no signing), with
    ``mav.seq`` set per frame.
  - pySerialTransfer: ``tx_obj(value, pos, val_type_override=fmt)`` per field,
    then ``send(payload_len)``; the port is an in-memory object whose
    ``write()`` appends to a bytearray, so the packet is built but nothing
    touches hardware.
* **decode**: one stream of N concatenated frames -> decoded field values.
  - RoverLink: ``FrameDecoder().feed(stream)``.
  - pymavlink: ``MAVLink.parse_buffer(stream)`` (the library's bulk entry point;
    ``parse_char`` is the same code fed one buffer at a time).
  - pySerialTransfer: ``available()`` driven until the in-memory port is empty,
    plus ``rx_obj(fmt, pos)`` for every field of each packet (``available()``
    alone only fills ``rx_buff``; users need ``rx_obj`` to get values). The
    figure without ``rx_obj`` is also printed as "parse only".

Why this is fair
----------------
* Same payload size for every stack. The RoverLink message is picked at run
  time and the peers follow its ``PAYLOAD_SIZE``. The MAVLink message is the
  char-free ardupilotmega message whose payload length is nearest to that size
  (exact for most sizes; every size used is printed). The pySerialTransfer
  payload has the same field types as that MAVLink message, padded or
  trimmed to exactly the target size.
* Peer values are random and non-zero, so MAVLink 2 trailing-zero truncation
  cannot shrink frames; every frame's length is checked before timing.
* Parser objects and input data are built before timing starts. Timing uses
  ``time.perf_counter`` with the garbage collector paused, as ``timeit``
  does, and keeps the best of K repeats. Repeats go round-robin across stacks
  so clock drift and thermal effects hit every stack alike.
* After every timed run, untimed, the output is checked: exactly N frames,
  with the values that went in. A run that decodes nothing therefore fails
  loudly instead of reporting a huge rate.
* The pySerialTransfer port is the cheapest possible fake: no syscalls. A real
  pyserial port costs more per ``read()``, so its figures here are an upper
  bound.

This module times and reports; each stack is built in ``benchmarks/codec_peers/``.
Run ``python benchmarks/codec.py --help`` for options (``--json``, ``--quick``).
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import importlib.metadata
import json
import platform
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from codec_peers.common import DEFAULT_PAYLOAD_SIZE, BenchmarkError, Case, Skip, Stack
from codec_peers.mavlink import build_pymavlink
from codec_peers.roverlink import build_roverlink
from codec_peers.serialtransfer import build_pyserialtransfer


def time_case(case: Case) -> None:
    run = case.prepare()
    gc.collect()
    gc.disable()  # like timeit: keep collector pauses out of the figures
    try:
        t0 = time.perf_counter()
        result = run()
        elapsed = time.perf_counter() - t0
    finally:
        gc.enable()
    case.check(result)
    case.times.append(elapsed)


def figures(case: Case, n: int) -> dict[str, Any]:
    best = min(case.times)
    return {
        "frames_per_s": n / best,
        "us_per_frame": best / n * 1e6,
        "best_s": best,
        "times_s": case.times,
    }


def _version(dist: str) -> str | None:
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    p.add_argument("--frames", type=int, default=20_000, help="frames per run (default 20000)")
    p.add_argument(
        "--repeat",
        type=int,
        default=5,
        help="timed runs per case; best is kept (default 5)",
    )
    p.add_argument("--quick", action="store_true", help="smoke test: 3000 frames, 3 repeats")
    p.add_argument("--json", metavar="PATH", help="also write the figures as JSON to PATH")
    p.add_argument(
        "--chunk",
        type=int,
        default=0,
        help="bytes per RoverLink/pymavlink decoder call (default 0: the whole "
        "stream in one call); pySerialTransfer pulls bytes itself",
    )
    p.add_argument(
        "--payload-size",
        type=int,
        help=f"peer payload size in bytes (default: the RoverLink message's, else {DEFAULT_PAYLOAD_SIZE})",
    )
    p.add_argument("--roverlink-message", help="RoverLink message class name (default: automatic)")
    p.add_argument(
        "--mavlink-message",
        help="MAVLink message name, e.g. COMMAND_LONG (default: automatic)",
    )
    p.add_argument(
        "--require-roverlink",
        action="store_true",
        help="fail instead of skipping RoverLink",
    )
    p.add_argument("--seed", type=int, default=1, help="random seed for field values")
    args = p.parse_args(argv)
    if args.quick:
        args.frames, args.repeat = 3_000, 3
    if args.frames < 1 or args.repeat < 1:
        p.error("--frames and --repeat must be >= 1")
    if args.payload_size is not None and not 1 <= args.payload_size <= 254:
        p.error("--payload-size must be in 1..254")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    n = args.frames

    stacks: list[Stack] = []
    skipped: dict[str, str] = {}
    n_fields: int | None = None
    size = args.payload_size
    try:
        rl_stack, rl_cls = build_roverlink(n, args)
        stacks.append(rl_stack)
        n_fields = len([f for f in dataclasses.fields(rl_cls) if f.init])
        if size is None:
            size = rl_stack.payload_bytes
        elif size != rl_stack.payload_bytes:
            print(
                f"warning: peers use {size} B payloads but {rl_stack.message} has "
                f"{rl_stack.payload_bytes} B: the ratios are not like for like"
            )
    except Skip as exc:
        if args.require_roverlink:
            print(f"error: RoverLink unavailable: {exc}", file=sys.stderr)
            return 1
        skipped["roverlink"] = str(exc)
        print(f"RoverLink: skipped ({exc}); measuring peers only.")
    size = size or DEFAULT_PAYLOAD_SIZE

    for key, build in (
        ("pymavlink", build_pymavlink),
        ("pyserialtransfer", build_pyserialtransfer),
    ):
        try:
            stacks.append(build(n, size, n_fields, args))
        except Skip as exc:
            skipped[key] = str(exc)
            print(f"{key}: skipped ({exc})")

    # Round-robin the repeats so drift affects every stack equally.
    for _ in range(args.repeat):
        for stack in stacks:
            for case in stack.cases:
                time_case(case)

    results = {stack.key: stack_results(stack, n) for stack in stacks}
    ratios = compute_ratios(results)
    print_report(args, size, stacks, results, ratios)
    if args.json:
        write_json(args, size, results, skipped, ratios)
        print(f"\nwrote {args.json}")
    return 0


def stack_results(stack: Stack, n: int) -> dict[str, Any]:
    entry: dict[str, Any] = {
        "message": stack.message,
        "payload_bytes": stack.payload_bytes,
        "wire_bytes_per_frame": stack.wire_bytes_per_frame,
        "notes": stack.notes,
    }
    for case in stack.cases:
        entry[case.op] = figures(case, n)
    return entry


PEERS = (("pymavlink", "pymavlink"), ("pyserialtransfer", "pySerialTransfer"))


def compute_ratios(results: dict[str, Any]) -> dict[str, dict[str, float] | None]:
    """RoverLink frames/s divided by peer frames/s (> 1: RoverLink faster)."""
    ratios: dict[str, dict[str, float] | None] = {}
    for peer, _ in PEERS:
        ratios[f"roverlink/{peer}"] = (
            {
                op: results["roverlink"][op]["frames_per_s"] / results[peer][op]["frames_per_s"]
                for op in ("encode", "decode")
            }
            if "roverlink" in results and peer in results
            else None
        )
    return ratios


def print_report(
    args: argparse.Namespace,
    size: int,
    stacks: list[Stack],
    results: dict[str, Any],
    ratios: dict[str, dict[str, float] | None],
) -> None:
    feed = "the whole stream per call" if args.chunk <= 0 else f"{args.chunk} B per call"
    print(
        f"\nCodec throughput: {args.frames} frames, best of {args.repeat}, "
        f"Python {platform.python_version()} ({platform.machine()})"
    )
    print(f"target payload: {size} B; decoders fed {feed}")
    head = f"{'stack':<17}{'op':<18}{'frames/s':>11}{'us/frame':>9}{'payload':>9}{'wire':>8}  message"
    print(head)
    print("-" * len(head))
    for stack in stacks:
        for case in stack.cases:
            fig = results[stack.key][case.op]
            print(
                f"{stack.label:<17}{case.op:<18}{fig['frames_per_s']:>11,.0f}"
                f"{fig['us_per_frame']:>9.2f}{stack.payload_bytes:>7} B"
                f"{stack.wire_bytes_per_frame:>6.1f} B  {stack.message}"
            )
    for stack in stacks:
        for note in stack.notes:
            print(f"note: {stack.label}: {note}")
    if "roverlink" in results:
        print("\nRatios, RoverLink frames/s / peer frames/s (> 1: RoverLink faster):")
        for peer, label in PEERS:
            r = ratios[f"roverlink/{peer}"]
            if r is not None:
                print(f"  RoverLink/{label:<17} encode {r['encode']:6.2f}x   decode {r['decode']:6.2f}x")


def write_json(
    args: argparse.Namespace,
    size: int,
    results: dict[str, Any],
    skipped: dict[str, str],
    ratios: dict[str, dict[str, float] | None],
) -> None:
    packages = ("pymavlink", "pySerialTransfer", "fastcrc", "pyserial")
    doc = {
        "benchmark": "roverlink-codec",
        "params": {
            "frames": args.frames,
            "repeat": args.repeat,
            "chunk": args.chunk,
            "seed": args.seed,
            "target_payload_bytes": size,
        },
        "environment": {
            "python": platform.python_version(),
            "implementation": platform.python_implementation(),
            "platform": platform.platform(),
            "machine": platform.machine(),
            "packages": {d: _version(d) for d in packages},
        },
        "stacks": results,
        "skipped": skipped,
        "ratios": ratios,
    }
    Path(args.json).write_text(json.dumps(doc, indent=2) + "\n")


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BenchmarkError as exc:
        print(f"BENCHMARK INVALID: {exc}", file=sys.stderr)
        sys.exit(1)
