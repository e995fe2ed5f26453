#!/usr/bin/env python3
"""Runs every smtcal command line of README.md, docs/*.md and
examples/*/README.md, so the docs cannot drift from the program (CTest
docs_<document>, one test per document; tests/docs/README.md says how to
write docs for it).

    run_doc_commands.py --smtcal BUILD/smtcal --source REPO [-v] [--keep] [DOC.md ...]

What is a command. Code blocks are fenced (``` or ~~~) or indented by four
spaces. A block is a *command block* when one of its lines runs smtcal: it
starts with `smtcal `, `build/smtcal ` or `../../build/smtcal ` (after an
optional `$ ` prompt), or pipes into one of them. Lines ending in `\\` are
joined with the next, and so is an indented line after a synopsis (a
wrapped synopsis, or its description). In a block that uses `$ ` prompts
only the prompted lines are commands (the rest is output).

Synopsis or real command. An smtcal line with placeholders -- an UPPERCASE
word (FILE.place, CELL.toml, OUT, N), `[`, `]`, `...`, `<...>`, or `|`
between words (`default|paper`) -- is a synopsis. It is checked against
`smtcal <subcommand> --help`: the subcommand exists (`forward|inverse` is
each of them), every option it names is one the subcommand has (or a global
option), an option given a value takes one and a flag is given none, and
every value a synopsis lists for an option with a fixed set of values
(`--solver default|paper`) is in that set; options that exclude each other
must be alternatives (`[-o OUT | --in-place | --check]`), not separate
brackets. Text after two or more spaces
that starts with a plain lowercase word is the line's description.
Every other line of a command block is real and runs in bash
(`set -o pipefail`).

Where real commands run. Each document gets a fresh copy of the repository's
`examples/` and of every folder of test data its commands name (a path under
`tests/`), with `build/smtcal` and a `smtcal` on PATH both the tested binary.
A block runs in the first of these directories in which every input its
smtcal commands name exists (or is written by an earlier line of the block):
the copy's root (README's `examples/paper-cell/...` paths), then each
`examples/*/` folder in name order (docs that say `layers.place --cell
paper.cell.toml`). A block none of them fits fails, naming the inputs that
nothing makes: the docs must show how to make them. Its lines then run in
order in that directory; `cd DIR` moves the rest of the block. Blocks run in
the order of the document, in the same copy, so a block may use what an
earlier one wrote.

Exit codes. A command must exit 0, unless the line ends with a comment
`# exit N ...` (the reader sees it) or the block is preceded by
`<!-- exit N -->`, which holds for the block's last command.

Skips. SKIPS below is the whole list of commands not run, each with its
reason, printed when it applies.
"""

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

# (regex on the command, reason, applies) -- applies() is evaluated per run.
SKIPS = [
    (re.compile(r"^rs274\b"),
     "LinuxCNC's rs274 is not installed (tools/install-deps.sh installs linuxcnc-uspace)",
     lambda: shutil.which("rs274") is None),
]

SMTCAL = r"(?:(?:\.\./)*build/smtcal|smtcal)"
SMTCAL_START = re.compile(r"^" + SMTCAL + r"(?=\s|$)")
SMTCAL_PIPED = re.compile(r"\|\s*" + SMTCAL + r"(?=\s|$)")
EXIT_COMMENT = re.compile(r"\s#\s*exit (\d+)\b[^#]*$")
EXIT_MARK = re.compile(r"^\s*<!--\s*exit (\d+)\s*-->\s*$")
PLACEHOLDER = re.compile(r"(?<![\w./-])(?:[A-Z][A-Z0-9_]*)(?:\.[A-Za-z0-9.]+)?(?![\w/-])"
                         r"|[\[\]]|\.\.\.|…|<[^>\s]+>|\w\|\w")
OUTPUT_OPTIONS = {"-o", "--output", "--report", "--svg", "--csv", "--setup-sheet", "--setup-csv"}
PATH_LIKE = re.compile(r"/|\.(place|toml|csv|json|pos|txt|tsv|mnt|mnb|ngc|ini|svg)$")
TIMEOUT_S = 300


class Line:
    def __init__(self, doc, lineno, text, expect=None):
        self.doc, self.lineno, self.text, self.expect = doc, lineno, text, expect

    def where(self):
        return f"{self.doc}:{self.lineno}"


def is_smtcal(text):
    return bool(SMTCAL_START.match(text) or SMTCAL_PIPED.search(text))


def code_blocks(path):
    """Yields (first line number, [(line number, text)], exit mark) per code block."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    i, mark, prev_blank = 0, None, True
    while i < len(lines):
        line = lines[i]
        fence = re.match(r"^\s*(```|~~~)", line)
        m = EXIT_MARK.match(line)
        if m:
            mark = int(m.group(1))
            i += 1
            continue
        if fence:
            body, j = [], i + 1
            while j < len(lines) and not lines[j].lstrip().startswith(fence.group(1)):
                body.append((j + 1, lines[j]))
                j += 1
            yield i + 1, body, mark
            mark, i, prev_blank = None, j + 1, False
            continue
        if prev_blank and (line.startswith("    ") or line.startswith("\t")) and line.strip():
            body, j = [], i
            while j < len(lines) and (lines[j].startswith("    ") or lines[j].startswith("\t") or not lines[j].strip()):
                body.append((j + 1, lines[j]))
                j += 1
            while body and not body[-1][1].strip():
                body.pop()
            indent = min(len(t) - len(t.lstrip()) for _, t in body if t.strip())
            yield i + 1, [(n, t[indent:]) for n, t in body], mark
            mark, i, prev_blank = None, j, False
            continue
        if line.strip():
            mark = None if not line.lstrip().startswith("<!--") else mark
        prev_blank = not line.strip()
        i += 1


def block_commands(doc, body, mark):
    """The block's command lines (continuations joined), or [] if it runs no smtcal."""
    prompted = any(t.startswith("$ ") for _, t in body)
    out, pending = [], None
    for n, t in body:
        if pending is not None:
            pending[1] += " " + t.strip()
        elif out and not prompted and t[:1].isspace() and is_synopsis(out[-1].text):
            out[-1].text += "  " + t.strip()  # a synopsis wrapped onto an indented line
            continue
        elif prompted:
            if not t.startswith("$ "):
                continue
            pending = [n, t[2:].strip()]
        else:
            if not t.strip() or t.lstrip().startswith("#"):
                continue
            pending = [n, t.strip()]
        if pending[1].endswith("\\"):
            pending[1] = pending[1][:-1].rstrip()
            continue
        out.append(Line(doc, pending[0], pending[1]))
        pending = None
    if pending is not None:
        out.append(Line(doc, pending[0], pending[1]))
    if not any(is_smtcal(c.text) for c in out):
        return []
    for c in out:
        m = EXIT_COMMENT.search(c.text)
        if m:
            c.expect = int(m.group(1))
    if mark is not None:
        out[-1].expect = mark
    return out


def is_synopsis(text):
    return bool(SMTCAL_START.match(text)) and bool(PLACEHOLDER.search(text))


# --- synopsis checks ---------------------------------------------------------

class Help:
    def __init__(self, smtcal):
        self.smtcal, self.cache = smtcal, {}

    def get(self, path):
        """(subcommands, {option: (takes_value, choices or None)}) of `smtcal PATH --help`, or None."""
        key = tuple(path)
        if key not in self.cache:
            r = subprocess.run([self.smtcal, *path, "--help"], capture_output=True, text=True)
            self.cache[key] = None if r.returncode != 0 else self.parse(r.stdout)
        return self.cache[key]

    @staticmethod
    def parse(text):
        subcommands, options, section = set(), {}, None
        for line in text.split("\n"):
            if re.match(r"^\S.*:$", line):
                section = line[:-1]
                continue
            if section == "Subcommands":
                m = re.match(r"^  (\S+)", line)
                if m:
                    subcommands.add(m.group(1))
            elif section == "Options":
                m = re.match(r"^  (-[^\s]*)(.*)$", line)
                if not m:
                    continue
                rest = m.group(2).strip()
                takes_value = bool(re.match(r"^[A-Z]+(?=[:=\s]|$)", rest))
                choices = None
                c = re.match(r"^[A-Z]+:\{([^}]*)\}", rest)
                if c:
                    choices = set(c.group(1).split(","))
                e = re.search(r"Excludes:((?:\s+-[\w-]+)+)", rest)
                excludes = set(e.group(1).split()) if e else set()
                names = m.group(1).split(",")
                for name in names:
                    options[name] = (takes_value, choices, names[-1], excludes)
        return subcommands, options


def strip_description(text):
    # `smtcal check FILE.place        parse + semantic checks`
    m = re.search(r"\s{2,}(?=[a-z][a-z']*(\s|$))", text)
    return text[:m.start()] if m else text


def check_synopsis(line, helps):
    """A list of problems with one synopsis line."""
    tokens = strip_description(line.text).split()[1:]
    problems = []
    paths = [[]]
    while tokens and re.fullmatch(r"[a-z][a-z-]*(\|[a-z][a-z-]*)*", tokens[0]):
        parent = helps.get(paths[0])
        if parent is None or not all(alt in parent[0] for alt in tokens[0].split("|")):
            break
        paths = [p + [alt] for p in paths for alt in tokens[0].split("|")]
        tokens.pop(0)
    if paths == [[]]:
        return [f"no smtcal subcommand in '{line.text}'"]
    global_options = helps.get([])[1]
    for path in paths:
        name = "smtcal " + " ".join(path)
        help_ = helps.get(path)
        if help_ is None:
            problems.append(f"'{name} --help' fails")
            continue
        options = {**global_options, **help_[1]}
        group, groups, depth, seen = 0, {}, 0, []  # option -> (bracket group, alternative in it)
        for tok in tokens:
            if depth == 0 and tok.startswith("["):
                group += 1
                alternative = 0
            if depth > 0 and tok == "|":
                alternative += 1
            depth += tok.count("[") - tok.count("]")
            m = re.fullmatch(r"\[*(--?[A-Za-z][\w-]*)(=\S*)?\]*\|?", tok)
            if m and m.group(1) in options:
                groups[options[m.group(1)][2]] = (group, alternative) if depth > 0 or tok.endswith("]") else (None, 0)
                seen.append(m.group(1))
        for a in seen:
            for b in seen:
                ga, gb = groups[options[a][2]], groups[options[b][2]]
                if options[b][2] in options[a][3] and a < b and not (ga[0] is not None and ga[0] == gb[0] and ga[1] != gb[1]):
                    problems.append(f"{name}: {a} and {b} exclude each other, but the synopsis lets them be combined")
        for i, tok in enumerate(tokens):
            bare = tok.lstrip("[").rstrip("]|")
            m = re.fullmatch(r"(--?[A-Za-z][\w-]*)(?:=(.*))?", bare)
            if not m:
                continue
            opt, value = m.group(1), m.group(2)
            if opt not in options:
                problems.append(f"{name} has no option {opt}")
                continue
            takes_value, choices = options[opt][:2]
            if value is None and not tok.endswith(("]", "|")) and i + 1 < len(tokens) \
                    and not tokens[i + 1].startswith(("-", "[", "|", "]")):
                value = tokens[i + 1].rstrip("]")
            if value is None:
                if takes_value:
                    problems.append(f"{name} {opt} takes a value; the synopsis gives none")
                continue
            if not takes_value:
                problems.append(f"{name} {opt} is a flag; the synopsis gives it the value '{value}'")
                continue
            literals = [v for v in value.split("|") if not PLACEHOLDER.fullmatch(v) and re.fullmatch(r"[a-z][\w-]*", v)]
            if choices is not None:
                for v in literals:
                    if v not in choices:
                        problems.append(f"{name} {opt} does not accept '{v}' (it takes {', '.join(sorted(choices))})")
            elif "|" in value and literals:
                problems.append(f"{name} {opt} lists values {value}, but --help names no set of values")
    return problems


# --- real commands -----------------------------------------------------------

def smtcal_files(text):
    """(inputs, outputs): the file arguments of the smtcal commands in one line."""
    inputs, outputs = [], []
    for part in re.split(r"\|", text):
        try:
            words = shlex.split(part, comments=True)
        except ValueError:
            continue
        if not words or not SMTCAL_START.match(" ".join(words[:1]) + " "):
            continue
        i = 1
        while i < len(words):
            w = words[i]
            if w in OUTPUT_OPTIONS and i + 1 < len(words):
                outputs.append(words[i + 1])
                i += 2
                continue
            if "=" in w and w.split("=", 1)[0] in OUTPUT_OPTIONS:
                outputs.append(w.split("=", 1)[1])
            elif w != "-" and not w.startswith("-") and PATH_LIKE.search(w):
                inputs.append(w)
            elif w.startswith("--") and "=" in w and PATH_LIKE.search(w.split("=", 1)[1]):
                inputs.append(w.split("=", 1)[1])
            i += 1
    return inputs, outputs


def shell_outputs(text):
    """What a shell line writes: `> FILE`, the target of cp/mkdir/touch."""
    outs = re.findall(r">\s*([^\s|;&]+)", text)
    try:
        words = shlex.split(text, comments=True)
    except ValueError:
        words = []
    if words and words[0] in ("cp", "mv") and len(words) >= 3:
        outs.append(words[-1])
    if words and words[0] in ("mkdir", "touch"):
        outs += [w for w in words[1:] if not w.startswith("-")]
    return outs


def missing_inputs(commands, start, root):
    """The inputs of the block that neither exist nor are made earlier in it, starting in START."""
    cwd, made, missing = start, set(), []
    for c in commands:
        words = c.text.split()
        if words[:1] == ["cd"] and len(words) == 2:
            cwd = os.path.normpath(os.path.join(cwd, words[1]))
            continue
        inputs, outputs = smtcal_files(c.text) if is_smtcal(c.text) else ([], [])
        for f in inputs:
            p = os.path.normpath(os.path.join(cwd, f))
            if not os.path.exists(p) and not any(p == m or p.startswith(m + os.sep) for m in made):
                missing.append(f)
        for f in outputs + shell_outputs(c.text):
            made.add(os.path.normpath(os.path.join(cwd, f)))
    return missing


def prepare_copy(source, smtcal, data_dirs):
    root = tempfile.mkdtemp(prefix="smtcal-docs-")
    shutil.copytree(os.path.join(source, "examples"), os.path.join(root, "examples"))
    for d in sorted(data_dirs):
        shutil.copytree(os.path.join(source, d), os.path.join(root, d), dirs_exist_ok=True)
    os.makedirs(os.path.join(root, "build"))
    os.makedirs(os.path.join(root, ".bin"))
    os.symlink(smtcal, os.path.join(root, "build", "smtcal"))
    os.symlink(smtcal, os.path.join(root, ".bin", "smtcal"))
    return root


def test_data_dirs(commands, source):
    dirs = set()
    for c in commands:
        for w in re.findall(r"(?<![\w./-])(tests/[\w./-]+)", c.text):
            p = os.path.join(source, w)
            if os.path.isdir(p):
                dirs.add(w.rstrip("/"))
            elif os.path.exists(p):
                dirs.add(os.path.dirname(w))
    return dirs


def run_doc(doc, blocks, args, helps, report):
    """Runs one document's blocks; appends failures to report. Returns (run, skipped) counts."""
    all_commands = [c for _, cmds in blocks for c in cmds]
    root = prepare_copy(args.source, args.smtcal, test_data_dirs(all_commands, args.source))
    env = dict(os.environ, PATH=os.path.join(root, ".bin") + os.pathsep + os.environ.get("PATH", ""),
               LC_ALL="C.UTF-8")
    candidates = [root] + sorted(os.path.join(root, "examples", d) for d in os.listdir(os.path.join(root, "examples"))
                                 if os.path.isdir(os.path.join(root, "examples", d)))
    ran = skipped = 0
    for first, commands in blocks:
        real = [c for c in commands if not is_synopsis(c.text)]
        for c in commands:
            if is_synopsis(c.text):
                for p in check_synopsis(c, helps):
                    report.append(f"{c.where()}: synopsis: {p}\n    {c.text}")
                ran += 1
        if not real:
            continue
        cwd = next((d for d in candidates if not missing_inputs(real, d, root)), None)
        if cwd is None:
            report.append(f"{doc}:{first}: no directory has the block's inputs; nothing in the docs makes "
                          f"{', '.join(sorted(set(missing_inputs(real, root, root))))}\n    "
                          + "\n    ".join(c.text for c in real))
            continue
        for c in real:
            words = c.text.split()
            if words[:1] == ["cd"] and len(words) == 2:
                cwd = os.path.normpath(os.path.join(cwd, words[1]))
                if not os.path.isdir(cwd):
                    report.append(f"{c.where()}: cd: no directory {words[1]}")
                    break
                continue
            skip = next((reason for rx, reason, applies in SKIPS if rx.search(c.text) and applies()), None)
            if skip:
                print(f"{c.where()}: skipped: {c.text}\n    ({skip})")
                skipped += 1
                continue
            expect = 0 if c.expect is None else c.expect
            start = time.monotonic()
            try:
                r = subprocess.run(["bash", "-o", "pipefail", "-c", c.text], cwd=cwd, env=env,
                                   capture_output=True, text=True, timeout=TIMEOUT_S)
                code, out, err = r.returncode, r.stdout, r.stderr
            except subprocess.TimeoutExpired:
                code, out, err = "timeout", "", f"still running after {TIMEOUT_S} s"
            ran += 1
            rel = os.path.relpath(cwd, root)
            if args.verbose:
                print(f"{c.where()}: [{rel}] exit {code} in {time.monotonic() - start:.1f} s: {c.text}")
            if code != expect:
                tail = "\n".join((err.strip() or out.strip()).split("\n")[-25:])
                report.append(f"{c.where()}: exit {code}, expected {expect} (in {rel})\n    {c.text}\n"
                              + "".join(f"    | {l}\n" for l in tail.split("\n") if tail))
    if args.keep:
        print(f"{doc}: kept {root}")
    else:
        shutil.rmtree(root, ignore_errors=True)
    return ran, skipped


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--smtcal", required=True, help="the smtcal binary")
    ap.add_argument("--source", required=True, help="the repository (README.md, docs/, examples/)")
    ap.add_argument("--keep", action="store_true", help="keep the temporary copies")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every command run")
    ap.add_argument("docs", nargs="*",
                    help="documents relative to --source (default README.md docs/*.md examples/*/README.md)")
    args = ap.parse_args()
    args.smtcal = os.path.abspath(args.smtcal)
    args.source = os.path.abspath(args.source)
    docs = args.docs or (["README.md"]
                         + sorted("docs/" + f for f in os.listdir(os.path.join(args.source, "docs")) if f.endswith(".md"))
                         + sorted(f"examples/{d}/README.md" for d in os.listdir(os.path.join(args.source, "examples"))
                                  if os.path.isfile(os.path.join(args.source, "examples", d, "README.md"))))
    helps = Help(args.smtcal)
    if helps.get([]) is None:
        print(f"error: {args.smtcal} --help fails")
        return 1
    report, total, skipped, start = [], 0, 0, time.monotonic()
    for doc in docs:
        blocks = []
        for first, body, mark in code_blocks(os.path.join(args.source, doc)):
            commands = block_commands(doc, body, mark)
            if commands:
                blocks.append((first, commands))
        ran, sk = run_doc(doc, blocks, args, helps, report)
        total, skipped = total + ran, skipped + sk
    for r in report:
        print("FAIL " + r)
    print(f"{total} command lines checked in {len(docs)} documents, {skipped} skipped, "
          f"{len(report)} failed ({time.monotonic() - start:.1f} s)")
    return 1 if report else 0


if __name__ == "__main__":
    sys.exit(main())
