"""CPU time of a running `hpge-cv generate` run, kept with its folder (issue 59's learning curves).

    python3 data/training/cpu.py DIR [ROWS_AT_START]

Finds the `generate` process writing DIR, reads its CPU time (user + system, /proc/PID/stat)
and its rows so far, and records them in DIR/cpu.json as the segment of that process (a run
resumed by a new process starts a new segment). `cpu_per_row_s` is the CPU time of all segments
over the rows they wrote; `solver_revision` is the run's (its generate.json). The `seconds` column of the rows is wall time, which other work on the
cores inflates; this is the processor time the rows cost. Run it now and then while the run
goes, and last just before stopping it: the rows a process wrote after the last call are not
counted. ROWS_AT_START: the rows the folder had when the process started, for a first call
made after it wrote some (default: where the last recorded segment ended, or for a run's first
process the rows now). Prints the record.
"""
import json
import os
import sys


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: python3 data/training/cpu.py DIR [ROWS_AT_START]")
    folder = sys.argv[1].rstrip("/")
    rows_file = os.path.join(folder, "rows.csv")
    if not os.path.isfile(rows_file):
        sys.exit(f"cpu.py: {rows_file} does not exist (not a generate folder)")
    pid = None
    for p in os.listdir("/proc"):
        if not p.isdigit():
            continue
        try:
            cmd = open(f"/proc/{p}/cmdline", "rb").read().split(b"\0")
        except OSError:
            continue
        args = [a.decode(errors="replace") for a in cmd]
        if "generate" in args and "--out" in args:
            out = args[args.index("--out") + 1].rstrip("/")
            if os.path.abspath(out) == os.path.abspath(folder):
                pid = int(p)
    if pid is None:
        sys.exit(f"cpu.py: no running `hpge-cv generate --out {folder}`")
    stat = open(f"/proc/{pid}/stat").read()
    fields = stat[stat.rindex(")") + 2:].split()
    ticks = os.sysconf("SC_CLK_TCK")
    cpu_s = (int(fields[11]) + int(fields[12])) / ticks
    start_ticks = int(fields[19])
    with open(rows_file) as f:
        rows = sum(1 for _ in f) - 1
    path = os.path.join(folder, "cpu.json")
    record = json.load(open(path)) if os.path.exists(path) else {"segments": []}
    segs = record["segments"]
    key = f"{pid}:{start_ticks}"
    if segs and segs[-1]["process"] == key:
        seg = segs[-1]
    else:
        # A resumed run: it started where the last recorded segment ended (rows written after
        # that segment's last call are then counted here, without their CPU time: call this
        # just before stopping a run).
        default = segs[-1]["rows"] if segs else rows
        at_start = int(sys.argv[2]) if len(sys.argv) == 3 else default
        seg = {"process": key, "rows_at_start": at_start}
        segs.append(seg)
    seg["rows"] = rows
    seg["cpu_s"] = cpu_s
    written = sum(s["rows"] - s["rows_at_start"] for s in segs)
    total = sum(s["cpu_s"] for s in segs)
    record["rows_written"] = written
    record["cpu_s"] = total
    record["cpu_per_row_s"] = total / written if written else None
    # The rows' solver revision (from the run's generate.json), so that a page quoting these
    # figures says which physics made them (`hpge-cv report numbers`).
    gen = os.path.join(folder, "generate.json")
    if os.path.exists(gen):
        record["solver_revision"] = json.load(open(gen)).get("solver_revision")
    with open(path + ".tmp", "w") as f:
        json.dump(record, f, indent=1)
        f.write("\n")
    os.replace(path + ".tmp", path)
    print(json.dumps({k: record[k] for k in ("rows_written", "cpu_s", "cpu_per_row_s")}))


main()
