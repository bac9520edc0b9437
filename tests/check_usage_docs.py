#!/usr/bin/python3
"""Every command and flag `fredholm --help` lists is documented in docs/usage.md.

  tests/check_usage_docs.py FREDHOLM docs/usage.md

Runs `FREDHOLM --help`, takes the subcommands it lists, runs `FREDHOLM COMMAND --help` for
each, and collects every flag named in their Options sections (long `--name` and short
`-x`). Each must appear in the usage document as a whole word (`--env` is not found inside
`--env-map`), and each command as `fredholm COMMAND`. Exits 1 listing what is missing, or
when the help output yielded no flags at all (so the check cannot pass on empty input).
Standard library only.
"""
import re
import subprocess
import sys

# An option line of CLI11's help: two spaces, then names separated by commas
# ("  -o,--output TEXT ...", "  --width INT=512 ...").
OPTION_LINE = re.compile(r"^  ((?:--?[A-Za-z0-9][\w-]*)(?:,--?[A-Za-z0-9][\w-]*)*)(?:\s|$)")
# A command line in the Subcommands section: two spaces, a name, then its description.
COMMAND_LINE = re.compile(r"^  ([a-z][\w-]*)(?:\s|$)")


def help_text(binary, args):
    command = [binary] + args + ["--help"]
    try:
        run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        sys.exit("check_usage_docs: cannot run %s: %s" % (" ".join(command), e))
    if run.returncode != 0:
        sys.exit("check_usage_docs: %s exited with %d:\n%s" % (" ".join(command), run.returncode, run.stdout))
    return run.stdout


def sections(text):
    """The help's sections by heading ("Options", "Subcommands"): their lines."""
    found, current = {}, None
    for line in text.splitlines():
        heading = re.match(r"^([A-Z][A-Za-z ]*):\s*$", line)
        if heading:
            current = heading.group(1)
            found.setdefault(current, [])
        elif current is not None and line.strip():
            found[current].append(line)
    return found


def flags_of(text):
    flags = []
    for line in sections(text).get("Options", []):
        m = OPTION_LINE.match(line)
        if m:
            flags.extend(m.group(1).split(","))
    return flags


def documented(doc, word):
    return re.search(r"(?<![\w-])" + re.escape(word) + r"(?![\w-])", doc) is not None


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_usage_docs.py FREDHOLM USAGE.md")
    binary, usage = sys.argv[1], sys.argv[2]
    with open(usage, encoding="utf-8") as f:
        doc = f.read()

    top = help_text(binary, [])
    commands = []
    for line in sections(top).get("Subcommands", []):
        m = COMMAND_LINE.match(line)
        if m:
            commands.append(m.group(1))

    wanted = [("fredholm", flag) for flag in flags_of(top)]
    for command in commands:
        wanted += [("fredholm " + command, flag) for flag in flags_of(help_text(binary, [command]))]

    if not wanted or not commands:
        print("check_usage_docs: found %d flags and %d commands in the help output; expected some of each"
              % (len(wanted), len(commands)))
        return 1

    missing = ["%s %s" % (where, flag) for where, flag in wanted if not documented(doc, flag)]
    missing += ["command 'fredholm %s'" % c for c in commands if not documented(doc, "fredholm " + c)]
    if missing:
        print("check_usage_docs: %s does not document:" % usage)
        for m in missing:
            print("  " + m)
        return 1
    print("check_usage_docs: %d flags of %d commands, all documented in %s" % (len(wanted), len(commands), usage))
    return 0


if __name__ == "__main__":
    sys.exit(main())
