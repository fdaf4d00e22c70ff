#!/usr/bin/python3
"""Damages a bag for the damaged-bag test of map_from_bag (run with /usr/bin/python3).

usage: damage_bag.py truncate <in.bag> <out.bag> --fraction F
         the first F of the file's bytes: a bag cut short (its index, at the end, is gone)
       damage_bag.py unclose <in.bag> <out.bag>
         the file header's index position set to 0, as in a bag whose recording never closed
       damage_bag.py corrupt <in.bag> <out.bag> --chunks K [K ...]
         32 bytes flipped in the middle of the data of each chunk K (0-based, in file order;
         the chunk headers and the index stay intact); prints one line per chunk:
         "chunk K: <start>-<end> s" (record times relative to the bag's start)
       damage_bag.py recompress <in.bag> <out.bag> --compression none|bz2|lz4
         the same messages, record times and order, in chunks of that compression (not a
         damage: the bag to damage next)
       damage_bag.py flip <in.bag> <out.bag> --seed S --count N
         N random bytes after the file header inverted (chunks, their headers or the index):
         a fuzz case
"""
import argparse
import random
import shutil
import struct

import rosbag


def truncate(args):
    data = open(args.input, "rb").read()
    open(args.output, "wb").write(data[: int(len(data) * args.fraction)])


def unclose(args):
    data = bytearray(open(args.input, "rb").read())
    at = data.index(b"index_pos=", 0, 4096 + 13) + len(b"index_pos=")
    data[at : at + 8] = struct.pack("<Q", 0)
    open(args.output, "wb").write(bytes(data))


def corrupt(args):
    shutil.copyfile(args.input, args.output)
    with rosbag.Bag(args.input) as bag:
        chunks = sorted(bag._chunks, key=lambda c: c.pos)
        start = bag.get_start_time()
    with open(args.output, "r+b") as f:
        for k in args.chunks:
            chunk = chunks[k]
            f.seek(chunk.pos)
            (header_len,) = struct.unpack("<I", f.read(4))
            f.seek(chunk.pos + 4 + header_len)
            (data_len,) = struct.unpack("<I", f.read(4))
            middle = chunk.pos + 4 + header_len + 4 + data_len // 2
            f.seek(middle)
            flipped = bytes(b ^ 0xFF for b in f.read(32))
            f.seek(middle)
            f.write(flipped)
            print(f"chunk {k}: {chunk.start_time.to_sec() - start:.2f}-"
                  f"{chunk.end_time.to_sec() - start:.2f} s")


def recompress(args):
    with rosbag.Bag(args.input) as bag, rosbag.Bag(args.output, "w", compression=args.compression) as out:
        for topic, raw, time in bag.read_messages(raw=True):
            out.write(topic, raw, time, raw=True)


def flip(args):
    data = bytearray(open(args.input, "rb").read())
    rng = random.Random(args.seed)
    for _ in range(args.count):
        data[rng.randrange(13 + 4096, len(data))] ^= 0xFF
    open(args.output, "wb").write(bytes(data))


def main():
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("truncate")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--fraction", type=float, required=True)
    p = sub.add_parser("unclose")
    p.add_argument("input")
    p.add_argument("output")
    p = sub.add_parser("corrupt")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--chunks", type=int, nargs="+", required=True)
    p = sub.add_parser("recompress")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--compression", choices=["none", "bz2", "lz4"], required=True)
    p = sub.add_parser("flip")
    p.add_argument("input")
    p.add_argument("output")
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--count", type=int, required=True)
    args = parser.parse_args()
    {"truncate": truncate, "unclose": unclose, "corrupt": corrupt, "recompress": recompress,
     "flip": flip}[args.command](args)


if __name__ == "__main__":
    main()
