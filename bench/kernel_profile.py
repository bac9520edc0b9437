#!/usr/bin/python3
"""Where a PoCL kernel's time goes, by source function: a `perf record` of one fredholm run,
its samples attributed to the kernel's inlined functions.

  bench/kernel_profile.py [--fredholm build/fredholm] [--kernel megakernel] [--top 30]
                          -- render SCENE ARGS...   (or: -- bench SCENE ARGS...)

The kernels are built from source with `-g` (FREDHOLM_CL_OPTIONS) into fresh caches. PoCL runs a
work-group function it generates around the kernel (`_pocl_kernel_K_workgroup`) that has no
line table of its own, while the kernel function it was made from (`_pocl_kernel_K`) has
one; the two bodies are nearly the same instructions, so the work-group function's are
matched to the kernel's (difflib over opcodes and operands, addresses masked), and each
sample takes the inlining chain llvm-symbolizer gives for its matched address. Prints the
share of the kernel's samples per stage function (what the kernel calls), per innermost
function, per function with what it calls (inclusive), per call chain, per source line and per innermost loop of the machine code (with
the lines most sampled in it). Needs perf (Debian linux-perf), llvm-symbolizer (llvm) and
objdump (binutils).
"""
import argparse, bisect, collections, difflib, os, re, subprocess, sys, tempfile

import benchlib


def functions(disassembly):
    """{name: [(address, opcode, operands)]} from objdump -d."""
    out, current = {}, None
    for line in disassembly.splitlines():
        m = re.match(r"^([0-9a-f]+) <(.*)>:", line)
        if m:
            current = out.setdefault(m.group(2), [])
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$", line)
        if m and current is not None:
            current.append((int(m.group(1), 16), m.group(2), m.group(3)))
    return out


def shape(instruction):
    operands = re.sub(r"<[^>]*>", "", re.sub(r"0x[0-9a-f]+", "N", instruction[2]))
    return instruction[1] + " " + operands


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    benchlib.add_arguments(ap, "--binary")
    ap.add_argument("--kernel", default="megakernel")
    ap.add_argument("--top", type=int, default=30)
    args, command = benchlib.parse_with_rest(ap)
    if not command:
        ap.error("give the fredholm command after --, e.g. -- render scene.obj --spp 64")
    # The scratch folder (perf's record, the caches, the image) goes when the report is out.
    with tempfile.TemporaryDirectory(prefix="fh_profile_") as work:
        profile(args, command, work)


def profile(args, command, work):
    """Records `fredholm COMMAND` in the folder `work` and prints the kernel's samples by stage, innermost
    function, call chain, source line and innermost loop."""
    cache, data = os.path.join(work, "cache"), os.path.join(work, "perf.data")
    # Both caches fresh: a program loaded from fredholm's binary cache is compiled by PoCL
    # without the line table that -g gives a build from source.
    env = dict(FREDHOLM_CL_OPTIONS=(os.environ.get("FREDHOLM_CL_OPTIONS", "") + " -g").strip(),
               POCL_CACHE_DIR=cache, FREDHOLM_CACHE_DIR=os.path.join(work, "programs"))
    # A render's image goes to the scratch folder; other commands (bench) write none.
    image = ["-o", os.path.join(work, "image.pfm"), "--force"] if command[0] == "render" else []
    benchlib.run(["perf", "record", "-q", "-o", data, "--", args.binary] + command + image, env=env)

    kernel, workgroup = "_pocl_kernel_" + args.kernel, "_pocl_kernel_" + args.kernel + "_workgroup"
    samples = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym,symoff,dso"], capture_output=True,
                             text=True).stdout
    hits = collections.Counter()  # (shared object, offset in the work-group function) -> samples
    for line in samples.splitlines():
        m = re.match(r"\s*[0-9a-f]+\s+" + re.escape(workgroup) + r"\+0x([0-9a-f]+)\s+\((.*)\)", line)
        if m:
            hits[(m.group(2), int(m.group(1), 16))] += 1
    if not hits:
        sys.exit(f"kernel_profile: no samples in {workgroup} (is the kernel's name right?)")
    library = collections.Counter(so for so, _ in hits.elements()).most_common(1)[0][0]

    bodies = functions(subprocess.run(["objdump", "-d", "--no-show-raw-insn", library], capture_output=True,
                                      text=True).stdout)
    source, target = bodies[kernel], bodies[workgroup]
    matcher = difflib.SequenceMatcher(None, [shape(i) for i in source], [shape(i) for i in target], autojunk=False)
    to_source = {}
    for a, b, n in matcher.get_matching_blocks():
        for k in range(n):
            to_source[target[b + k][0] - target[0][0]] = source[a + k][0]
    matched = sorted(to_source)

    by_address = collections.Counter()
    for (so, offset), count in hits.items():
        if so != library:
            continue
        i = bisect.bisect_right(matched, offset) - 1  # an unmatched instruction goes with the one before it
        if i >= 0:
            by_address[to_source[matched[i]]] += count
    addresses = sorted(by_address)
    symbolized = subprocess.run(["llvm-symbolizer", "--inlining", "--obj=" + library],
                                input="\n".join(hex(a) for a in addresses), capture_output=True,
                                text=True).stdout.strip().split("\n\n")

    total = sum(by_address.values())
    stage, inner, chain, lines, inclusive = (collections.Counter() for _ in range(5))
    line_of = {}  # source address -> its innermost frame's function and file:line
    for address, frames in zip(addresses, symbolized):
        entries = frames.strip().split("\n")
        names = entries[0::2]
        count = by_address[address]
        inner[names[0]] += count
        line_of[address] = names[0]
        if len(entries) > 1:  # file:line:column of the innermost frame, column dropped
            line_of[address] = f"{names[0]} {os.path.basename(entries[1].rsplit(':', 1)[0])}"
            lines[line_of[address]] += count
        stage[names[-2] if len(names) >= 2 else names[-1]] += count
        chain[" < ".join(names[:4])] += count
        # A function's share with everything inlined into it, wherever it sits in the chain
        # (a stage's ray traversal within it, say): each function counted once per sample.
        for name in set(names):
            inclusive[name] += count
    print(f"{args.kernel}: {total} samples in {os.path.relpath(library, cache)}, "
          f"{len(to_source)} of {len(target)} instructions matched to the kernel's line table")
    for title, counter in (("stage (called by the kernel)", stage), ("innermost function", inner),
                           ("function, with what it calls (inclusive)", inclusive),
                           ("call chain", chain), ("source line", lines)):
        print(f"\n{title}:")
        for name, count in counter.most_common(args.top):
            print(f"  {100.0 * count / total:5.1f}%  {name}")
    print_loops(target, hits, library, matched, to_source, line_of, args.top)


def loops_of(body):
    """The loops of a disassembled function as (first, last) offsets from its start: a backward
    jump's target heads a loop that runs to the last jump back to it."""
    start, last = body[0][0], {}
    for address, opcode, operands in body:
        m = re.match(r"([0-9a-f]+)\b", operands)
        if opcode.startswith("j") and m and start <= int(m.group(1), 16) <= address:
            last[int(m.group(1), 16) - start] = address - start
    return sorted(last.items())


def print_loops(target, hits, library, matched, to_source, line_of, top):
    """Samples by the innermost loop of the work-group function they fall in, with the source
    lines most sampled in each. Compiler-made instructions (spills, address arithmetic, the
    mask moves around a comparison) carry no line or a neighbour's, so a loop's whole share
    says more about what a stretch of code costs than the per-line table does."""
    loops = loops_of(target)
    share, inside = collections.Counter(), collections.defaultdict(collections.Counter)
    for (so, offset), count in hits.items():
        if so != library:
            continue
        around = [lp for lp in loops if lp[0] <= offset <= lp[1]]
        loop = min(around, key=lambda lp: lp[1] - lp[0]) if around else None
        share[loop] += count
        i = bisect.bisect_right(matched, offset) - 1
        if i >= 0 and loop:
            inside[loop][line_of.get(to_source[matched[i]], "?")] += count
    sizes = {lp: sum(1 for a, _, _ in target if lp[0] <= a - target[0][0] <= lp[1]) for lp in share if lp}
    total = sum(share.values())
    print("\ninnermost loop (offsets in the work-group function; its three most sampled lines):")
    for loop, count in share.most_common(top):
        if loop is None:
            print(f"  {100.0 * count / total:5.1f}%  outside every loop")
            continue
        hot = ", ".join(f"{name} {100.0 * c / count:.0f}%" for name, c in inside[loop].most_common(3))
        print(f"  {100.0 * count / total:5.1f}%  {loop[0]:#x}-{loop[1]:#x} ({sizes[loop]} instructions): {hot}")


if __name__ == "__main__":
    benchlib.main(main)
