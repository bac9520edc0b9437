#!/usr/bin/python3
"""A stand-in for the tev viewer: listens where --display-server points, takes every packet a
render sends (tev's protocol: uint32 length, type byte, fields), and reports what came.
For bench/ab_speed.py (a render with a viewer attached against one without) and for trying
--display-server where tev is not installed.

usage: bench/tev_sink.py [--port 14158] [--quiet]
Runs until interrupted; after each connection closes it prints the images created and the
frames (full sets of update tiles) received.
"""
import argparse
import socket
import struct

NAMES = {4: "create", 6: "update"}


def packets(conn):
    buffer = b""
    while True:
        chunk = conn.recv(1 << 20)
        if not chunk:
            return
        buffer += chunk
        while len(buffer) >= 4:
            (length,) = struct.unpack_from("<I", buffer)
            if len(buffer) < length:
                break
            yield buffer[4], buffer[5:length]
            buffer = buffer[length:]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--port", type=int, default=14158)
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args()
    server = socket.create_server(("127.0.0.1", args.port))
    while True:
        conn, _ = server.accept()
        counts, size = {}, 0
        with conn:
            for kind, payload in packets(conn):
                counts[NAMES.get(kind, kind)] = counts.get(NAMES.get(kind, kind), 0) + 1
                size += len(payload) + 5
        if not args.quiet:
            print(f"connection closed: {counts}, {size / 1e6:.1f} MB", flush=True)


if __name__ == "__main__":
    main()
