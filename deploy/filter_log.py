#!/usr/bin/env python3
"""Copies the events of chosen channels from one LCM log file to another, byte for byte.

usage: deploy/filter_log.py IN.lcm OUT.lcm CHANNEL[,CHANNEL...] [FROM_S TO_S]

Every kept event keeps its event number, timestamp, channel and payload; the others are dropped.
FROM_S and TO_S keep only the events logged that many seconds after the log's first event.
Used to cut a small sample for an offline replay test out of a long recording (logs/README.md).
"""
import struct
import sys

SYNC = 0xEDA1DA01


def main(argv):
    if len(argv) not in (4, 6):
        sys.exit(__doc__)
    src, dst, channels = argv[1], argv[2], set(argv[3].split(","))
    window = (float(argv[4]), float(argv[5])) if len(argv) == 6 else None
    first_ts = None
    kept = total = 0
    with open(src, "rb") as f, open(dst, "wb") as out:
        while True:
            head = f.read(28)
            if not head:
                break
            if len(head) < 28:
                sys.exit(f"{src}: truncated event header after {total} events")
            sync, _num, ts, chan_len, data_len = struct.unpack(">IqqII", head)
            if sync != SYNC:
                sys.exit(f"{src}: bad sync word 0x{sync:08x} at event {total}: not an LCM log")
            body = f.read(chan_len + data_len)
            if len(body) < chan_len + data_len:
                sys.exit(f"{src}: truncated event {total}")
            total += 1
            first_ts = ts if first_ts is None else first_ts
            if window and not window[0] <= (ts - first_ts) * 1e-6 <= window[1]:
                continue
            if body[:chan_len].decode("utf-8", "replace") in channels:
                out.write(head + body)
                kept += 1
    print(f"kept {kept} of {total} events ({','.join(sorted(channels))}) -> {dst}")


if __name__ == "__main__":
    main(sys.argv)
