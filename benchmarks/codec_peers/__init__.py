"""The stacks benchmarks/codec.py measures, one module per stack: each builds a `Stack` whose
cases prepare (untimed) the callable that is timed and check (untimed) what it returned.

- `common`: the `Stack`/`Case` records, the errors and the helpers every stack uses.
- `mavlink`: pymavlink (MAVLink 2), and the choice of the MAVLink message the peers carry.
- `serialtransfer`: pySerialTransfer over an in-memory port.
- `roverlink`: RoverLink's `encode_frame` and `FrameDecoder`, on the message picked from the spec.
"""
