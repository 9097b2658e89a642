#!/usr/bin/python3
"""A stand-in for blurcue in the protocol fuzz's own test (session_protocol_fuzz_catches_unnamed): `validate FILE`
refuses every protocol with a line that names no field - the file alone, or nothing at all, as validate's "a level
must be a number or a string, got true" did - so the fuzz must count each one as unnamed and fail."""
import sys

if len(sys.argv) > 2 and sys.argv[1] == "validate":
    path = sys.argv[-1]
    if sum(path.encode()) % 2:
        print("blurcue: %s: the protocol is wrong somewhere" % path, file=sys.stderr)
    else:
        print("blurcue: a level must be a number or a string, got true", file=sys.stderr)
    sys.exit(3)
sys.exit(0)
