#!/usr/bin/env python3
"""Time quadrecomb builds or settings against each other, interleaved, on a noisy machine.

Each round runs every variant once on the same seed (the round number), in alternating order,
reading `time_s` from the command's `--json` output; the summary gives each variant's median
time and the median over rounds of its ratio to the first variant (the baseline). Single runs
on a shared VM vary by +-25 % even when it is quiet: use many rounds (25 or more).

  scripts/interleave.py --rounds 25 \\
      --variant base=/path/to/old/quadrecomb --variant new=target/release/quadrecomb \\
      -- recombine borouchaki --algo selective --horizon 5 --no-optimum --backend cpu

  # one build, two settings (the valid-quad rule against the paper's):
  scripts/interleave.py --rounds 25 --variant rule=target/release/quadrecomb \\
      --variant 'allow=target/release/quadrecomb --allow-invalid' \\
      -- recombine borouchaki --algo selective --horizon 1 --no-optimum --backend cpu

A variant is NAME=BINARY [EXTRA ARGS...] (extra arguments go after the common ones); the
command gets `--seed ROUND --json` appended. Builds compared on the same settings must make
the same quads: the summary says in how many rounds the variants' quad counts differed
(expected only when their settings differ, as with --allow-invalid).
"""
import argparse, json, shlex, statistics, subprocess, sys


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=25)
    ap.add_argument("--variant", action="append", required=True, help="NAME=BINARY [EXTRA ARGS]")
    ap.add_argument("command", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = a.command[1:] if a.command[:1] == ["--"] else a.command
    if not cmd or a.rounds < 1:
        ap.error("give a quadrecomb command after -- and at least one round")
    variants = []
    for v in a.variant:
        name, _, rest = v.partition("=")
        words = shlex.split(rest)
        if not name or not words:
            ap.error(f"--variant {v!r}: expected NAME=BINARY [EXTRA ARGS]")
        variants.append((name, words[0], words[1:]))
    times = {name: [] for name, _, _ in variants}
    differed = 0
    for r in range(a.rounds):
        order = variants if r % 2 == 0 else variants[::-1]
        quads = set()
        for name, binary, extra in order:
            out = subprocess.run([binary, *cmd, *extra, "--seed", str(r), "--json"],
                                 capture_output=True, text=True)
            if out.returncode != 0:
                sys.exit(f"{name}, round {r}: exit {out.returncode}: {out.stderr.strip()}")
            d = json.loads(out.stdout)
            times[name].append(d["time_s"])
            quads.add(d.get("quads"))
        differed += len(quads) != 1
    base = variants[0][0]
    print(f"{a.rounds} rounds, seeds 0..{a.rounds - 1}: {' '.join(cmd)}")
    for name, _, _ in variants:
        t = times[name]
        ratios = sorted(x / y for x, y in zip(t, times[base]))
        print(f"{name:>12}: median {statistics.median(t):.4f} s; per-round ratio to {base}: median "
              f"{statistics.median(ratios):.3f} (range {ratios[0]:.3f}-{ratios[-1]:.3f})")
    print(f"quad counts differed between the variants in {differed} of {a.rounds} rounds")


if __name__ == "__main__":
    main()
