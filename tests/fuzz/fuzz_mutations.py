"""Hypothesis strategies for the fuzz test of the command line (issue 17, item 9): mutated case
files (a shipped case with keys deleted, misspelt, retyped, set to extreme values, and YAML
tags, aliases, duplicate keys, broken bytes) and mutated command lines (``--set``, numeric
options, unknown options, output folders that cannot be used).

A drawn :class:`Example` is a recipe: the test writes its case file and builds its argv with its
own paths (see :meth:`Example.argv`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from hypothesis import strategies as st

from peridyn.io.case import parse_yaml

ROOT = Path(__file__).resolve().parents[2]
#: Every shipped case: the examples in cases/ and the demo's case.
SHIPPED = [
    *sorted((ROOT / "cases").glob("*.yaml")),
    ROOT / "src" / "peridyn" / "data" / "demo_plate_burst.yaml",
]
#: The tiny case that ``run`` and ``modal`` examples mutate: the bar of cases/bar_pulse.yaml at
#: 5 mm spacing (160 points) for 1 us, without figures (it builds in well under a second).
TINY_OVERRIDES = {
    ("discretization", "spacing"): 5.0e-3,
    ("solver", "time"): 1.0e-6,
    ("output", "plots"): False,
    ("output", "vtu"): False,
}
#: Memory limit of every run and modal example (the last --max-memory wins): a mutated tiny case
#: may not grow to more than about 100 MB of arrays over the interpreter's own 300 MB.
RUN_MEMORY_LIMIT = "400MB"

# ---------------------------------------------------------------------------- values

#: The values a number is replaced by: non-finite, signed zero, negative, huge, tiny, too large
#: for a C integer (issue 17, item 9: "extreme, NaN, inf, negative, huge values").
EXTREME_NUMBERS = [
    math.nan,
    math.inf,
    -math.inf,
    0,
    0.0,
    -0.0,
    -1,
    -1.0e-3,
    1.0e300,
    -1.0e300,
    1.0e-300,
    5.0e-324,
    10**30,
    2**63,
    -(2**63),
    2**31,
    1,
    2,
    3,
]
#: Strings no field expects: empty, blank, control characters, non-ASCII, right-to-left override,
#: YAML and shell syntax that must stay text, a path escape.
GARBAGE_STRINGS = [
    "",
    " ",
    "\t",
    "\x00",
    "\x1b[31mred",
    "\x7f",
    "caf\u00e9",
    "\u65e5\u672c",
    "\u202eevil",
    "\U0001f4a5",
    "1e-3 m",
    "0x1F",
    "NaN",
    ".inf",
    "yes",
    "~",
    "null",
    "${HOME}",
    "../../etc/passwd",
    "%s%n",
    "'",
    '"',
    "a" * 5000,
]
garbage_text = st.one_of(
    st.sampled_from(GARBAGE_STRINGS),
    st.text(st.characters(blacklist_categories=("Cs",)), max_size=12),
)
scalars = st.one_of(st.sampled_from(EXTREME_NUMBERS), st.booleans(), st.none(), garbage_text)
#: Any value of any type: scalars, empty and small lists and mappings.
values = st.one_of(
    scalars,
    st.builds(list),
    st.builds(dict),
    st.lists(scalars, max_size=4),
    st.dictionaries(st.one_of(garbage_text, st.sampled_from(EXTREME_NUMBERS)), scalars, max_size=3),
)


def typo(key: str):
    """A misspelling of ``key``: a letter dropped, doubled, swapped or changed, or the case flipped."""
    if not key:
        return st.just("x")
    return st.integers(0, len(key) - 1).flatmap(
        lambda i: st.sampled_from(
            [
                key[:i] + key[i + 1 :],
                key[:i] + key[i] + key[i:],
                key[:i] + key[i + 1 : i + 2] + key[i] + key[i + 2 :],
                key[:i] + ("x" if key[i] != "x" else "y") + key[i + 1 :],
                key.swapcase(),
                key + "_",
            ]
        )
    )


# ---------------------------------------------------------------------------- case mutations


def paths(node, prefix=()) -> list[tuple]:
    """Every key path in a nested mapping/list, parents before children (keys and list indices)."""
    found = []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, child in items:
        found.append((*prefix, key))
        found += paths(child, (*prefix, key))
    return found


def _parent(raw, path):
    node = raw
    for part in path[:-1]:
        node = node[part]
    return node


@st.composite
def structural_mutation(draw, raw: dict) -> str:
    """Change ``raw`` in place (delete, rename, retype, extreme value, empty, invented key);
    returns what was done."""
    where = paths(raw)
    kind = draw(st.sampled_from(["delete", "rename", "retype", "extreme", "empty", "invent"]))
    if kind == "invent" or not where:
        dicts = [()] + [p for p in where if isinstance(_parent(raw, (*p, None)), dict)]
        at = draw(st.sampled_from(dicts))
        node = _parent(raw, (*at, None))
        names = [str(k) for k in node] or ["key"]
        key = draw(st.one_of(st.sampled_from(names).flatmap(typo), garbage_text))
        node[key] = copy.deepcopy(draw(values))
        return f"invent {'.'.join(map(str, (*at, key)))!r}"
    path = draw(st.sampled_from(where))
    parent, key = _parent(raw, path), path[-1]
    label = ".".join(map(str, path))
    if kind == "delete":
        del parent[key]
        return f"delete {label}"
    if kind == "rename" and isinstance(parent, dict):
        new = draw(typo(str(key)))
        parent[new] = parent.pop(key)
        return f"rename {label} -> {new!r}"
    if kind == "rename":  # a list item has no name: change its value instead
        kind = "retype"
    if kind == "extreme":
        parent[key] = draw(st.sampled_from(EXTREME_NUMBERS))
    elif kind == "empty":
        parent[key] = draw(st.sampled_from([list, dict, lambda: None, str]))()
    else:
        parent[key] = copy.deepcopy(draw(values))
    return f"{kind} {label} = {parent[key]!r:.60}"


#: Whole files: empty, blank, a comment, a list, scalars, two documents, a null byte, a BOM alone,
#: deep nesting, a huge integer, an unsafe tag at the root.
WHOLE_FILES = [
    b"",
    b"   \n\n",
    b"# only a comment\n",
    b"- a\n- b\n",
    b"42\n",
    b"hello\n",
    b"null\n",
    b"~",
    b"[]",
    b"{}",
    b"---\nname: a\n---\nname: b\n",
    b"\x00",
    b"\xef\xbb\xbf",
    b"[" * 5000 + b"]" * 5000,
    b"{a: " * 500 + b"1" + b"}" * 500,
    b"name: " + b"9" * 5000 + b"\n",
    b"!!python/object/apply:os.system ['echo pwned']\n",
    b"\xff\xfe",
]
#: Tags a value is replaced by: Python objects (SafeLoader must refuse), binary, custom, set,
#: timestamp, and standard tags applied to text that is not of their type.
TAGS = [
    b"!!python/object/apply:os.system ['echo pwned']",
    b"!!python/object:builtins.dict {}",
    b"!!python/name:os.system",
    b"!!binary aGVsbG8=",
    b"!foo bar",
    b"!foo {a: 1}",
    b"!!set {a, b}",
    b"!!timestamp 2001-12-14",
    b"!!int abc",
    b"!!float x",
    b"!!bool maybe",
    b"!!str 3",
    b"!!omap [a: 1, b: 2]",
    b"!<tag:yaml.org,2002:str> x",
]
#: Bytes that are not UTF-8 (a lone continuation byte, an overlong form, a surrogate, above
#: U+10FFFF), control characters YAML refuses, and a tab where indentation is.
BAD_BYTES = [
    b"\xff",
    b"\xfe",
    b"\xc3\x28",
    b"\x80",
    b"\xc0\xaf",
    b"\xed\xa0\x80",
    b"\xf4\x90\x80\x80",
    b"\x07",
    b"\x1b",
    b"\x00",
]


def alias_bomb(levels: int) -> bytes:
    """Billion laughs: ``levels`` anchors of nine aliases each (9**levels values when expanded)."""
    lines = [b"lol0: &lol0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    for i in range(1, levels + 1):
        lines.append(f"lol{i}: &lol{i} [{', '.join([f'*lol{i - 1}'] * 9)}]".encode())
    return b"\n".join(lines) + b"\n"


def _value_lines(lines: list[bytes]) -> list[int]:
    """Indices of the lines that hold ``key: value``."""
    return [i for i, line in enumerate(lines) if b": " in line and not line.lstrip().startswith(b"#")]


@st.composite
def text_mutation(draw, text: bytes) -> tuple[bytes, str]:
    """The YAML ``text`` changed as bytes (tags, aliases, duplicate keys, broken bytes...)."""
    kind = draw(
        st.sampled_from(
            [
                "whole",
                "tag",
                "bomb",
                "alias",
                "undefined_alias",
                "merge",
                "duplicate",
                "bytes",
                "truncate",
                "tab",
                "crlf",
                "bom",
                "utf16",
            ]
        )
    )
    lines = text.split(b"\n")
    valued = _value_lines(lines) or [0]
    if kind == "whole":
        return draw(st.sampled_from(WHOLE_FILES)), "whole file"
    if kind == "tag":
        i = draw(st.sampled_from(valued))
        tag = draw(st.sampled_from(TAGS))
        lines[i] = lines[i].split(b": ", 1)[0] + b": " + tag
        return b"\n".join(lines), f"tag on line {i + 1}: {tag!r}"
    if kind == "bomb":
        levels = draw(st.integers(3, 12))
        bomb = alias_bomb(levels)
        if draw(st.booleans()) and valued != [0]:  # the bomb used as a value of the case
            i = draw(st.sampled_from(valued))
            lines[i] = lines[i].split(b": ", 1)[0] + f": *lol{levels}".encode()
        return bomb + b"\n".join(lines), f"alias bomb of {levels} levels"
    if kind in ("alias", "undefined_alias", "merge"):
        i, j = draw(st.sampled_from(valued)), draw(st.sampled_from(valued))
        if kind == "alias":
            lines[i] = lines[i].replace(b": ", b": &anchor ", 1)
        if kind == "merge":  # a merge key into a mapping that has a key at line j's indentation
            indent = lines[j][: len(lines[j]) - len(lines[j].lstrip())]
            lines.insert(j, indent + b"<<: *anchor")
        else:
            lines[j] = lines[j].split(b": ", 1)[0] + b": *anchor"
        return b"\n".join(lines), f"{kind} lines {i + 1} -> {j + 1}"
    if kind == "duplicate":
        i = draw(st.integers(0, len(lines) - 1))
        lines.insert(i, lines[i])
        return b"\n".join(lines), f"line {i + 1} twice"
    if kind == "bytes":
        at = draw(st.integers(0, len(text)))
        bad = draw(st.sampled_from(BAD_BYTES))
        return text[:at] + bad + text[at:], f"{bad!r} at byte {at}"
    if kind == "truncate":
        at = draw(st.integers(0, len(text)))
        return text[:at], f"cut at byte {at}"
    if kind == "tab":
        i = draw(st.integers(0, len(lines) - 1))
        lines[i] = b"\t" + lines[i].lstrip(b" ")
        return b"\n".join(lines), f"tab on line {i + 1}"
    if kind == "crlf":
        return text.replace(b"\n", b"\r\n"), "CRLF line ends"
    if kind == "bom":
        return b"\xef\xbb\xbf" + text, "UTF-8 byte order mark"
    return text.decode("utf-8").encode("utf-16"), "UTF-16"


def base_case(path: Path, tiny: bool = False) -> dict:
    """The shipped case at ``path`` as a mapping; with ``tiny``, with :data:`TINY_OVERRIDES`."""
    raw = parse_yaml(path.read_text())  # peridyn's reading: 1.0e-3 is a number
    if tiny:
        for (section, key), value in TINY_OVERRIDES.items():
            raw.setdefault(section, {})[key] = value
    return raw


def dump(raw) -> bytes:
    """``raw`` as YAML text (a NaN as ``.nan``, control characters escaped)."""
    return yaml.safe_dump(raw, sort_keys=False, allow_unicode=True).encode("utf-8")


def _reversed(node):
    """``node`` with the keys of every mapping in reverse order (the same case)."""
    if isinstance(node, dict):
        return {k: _reversed(node[k]) for k in reversed(node)}
    return [_reversed(v) for v in node] if isinstance(node, list) else node


#: Changes that keep the case what it was: flow style, key order, comments, CRLF, a BOM.
BENIGN = {
    "flow style": lambda raw: yaml.safe_dump(raw, default_flow_style=True, allow_unicode=True).encode(),
    "keys reversed": lambda raw: dump(_reversed(raw)),
    "comments": lambda raw: b"# a comment\n" + dump(raw).replace(b"\n", b"  # trailing\n"),
    "CRLF": lambda raw: dump(raw).replace(b"\n", b"\r\n"),
    "BOM": lambda raw: b"\xef\xbb\xbf" + dump(raw),
    "as shipped": dump,
}


@st.composite
def mutated_case(draw, raw: dict) -> tuple[bytes, list[str]]:
    """``raw`` (left unchanged) with 1-3 structural mutations (mostly one), one of its text, or
    one that keeps it valid (so that the checks after the schema are reached): (file bytes, what
    was done)."""
    raw = copy.deepcopy(raw)
    kind = draw(st.sampled_from(["structural", "structural", "structural", "text", "benign", "benign"]))
    if kind == "text":
        text, what = draw(text_mutation(dump(raw)))
        return text, [what]
    if kind == "benign":
        what = draw(st.sampled_from(sorted(BENIGN)))
        return BENIGN[what](raw), [what]
    done = [draw(structural_mutation(raw)) for _ in range(draw(st.sampled_from([1, 1, 1, 2, 3])))]
    return dump(raw), done


# ---------------------------------------------------------------------------- command lines

#: Values for options that take a count (``--checkpoint-every``, ``--modes``) or a size
#: (``--max-memory``): good, zero, negative, non-finite, fractional, huge, non-ASCII digits, units.
NUMBER_TEXTS = [
    "3",
    "0",
    "-5",
    "1.5",
    "1e300",
    "1e400",
    "nan",
    "inf",
    "-inf",
    "",
    " ",
    "x",
    "0x10",
    "1_000",
    "99999999999999999999999999999",
    "\u0661\u0662",
    "4GB",
    "512MiB",
    "-1GB",
    "nanGB",
    "1e999TB",
    "1 KB",
    "GB",
    "10%",
]
#: --set values whose YAML is broken, tagged, aliased or odd.
BROKEN_YAML = [
    "[0.1,0.01",
    "{a: 1",
    "{a",
    '"unterminated',
    "'",
    "- - -",
    ": :",
    "*undefined",
    "&a",
    "!!python/object/apply:os.system ['true']",
    "!foo x",
    "!!binary aGVsbG8=",
    "[" * 200 + "]" * 200,
    "a: b: c",
    "\t",
    "%YAML 1.1",
    "---",
    "...",
    "@x",
    "`x`",
]
#: Options that are never drawn: --help (SystemExit, by design), --debug (asks for the traceback),
#: and --overwrite/--restart aimed at the earlier run (allowed to change it) are added on purpose.
NEVER = ("-h", "--help", "--debug", "--overwrite", "--restart")
#: Every option of run, validate and modal: invented options must not be prefixes of any
#: (argparse takes an unambiguous prefix for the option).
KNOWN_OPTIONS = [
    "--set",
    "--output",
    "--checkpoint-every",
    "--restart",
    "--progress",
    "--no-progress",
    "--json",
    "--debug",
    "--max-memory",
    "--overwrite",
    "--build",
    "--modes",
    "--compare",
    "--help",
    "--version",
]


def _not_a_prefix(option: str) -> bool:
    return option.startswith("-") and not any(known.startswith(option) for known in KNOWN_OPTIONS)


unknown_options = st.one_of(
    st.sampled_from(
        ["--sett", "--outptu", "--jsno", "--checkpoint_every", "--max_memory", "-x", "--=", "---"]
    ),
    st.sampled_from(KNOWN_OPTIONS).flatmap(typo).map(lambda o: o if o.startswith("--") else "--" + o),
).filter(_not_a_prefix)


def _flow_yaml(value) -> str:
    """``value`` as one line of YAML."""
    return yaml.safe_dump(value, default_flow_style=True, width=10**6).strip().removesuffix("...").strip()


def set_items(raw: dict):
    """``--set`` items: an existing or invented key path (list items by index) = a YAML value,
    or an item without ``=``."""
    keys = [".".join(map(str, p)) for p in paths(raw)] or ["name"]
    key = st.one_of(st.sampled_from(keys), st.sampled_from(keys).flatmap(typo), garbage_text)
    value = st.one_of(
        st.sampled_from(BROKEN_YAML),
        values.map(_flow_yaml),
        garbage_text,
    )
    return st.one_of(
        st.tuples(key, value).map(lambda kv: f"{kv[0]}={kv[1]}"),
        garbage_text.filter(lambda s: "=" not in s),
    )


#: Added to a ``--restart`` aimed at the earlier run: a case it was not made by (the case hash
#: leaves out the run length, so a case of the same material could continue the run).
RESTART_CHANGE = ["--set", "material.E=150.0e9"]
#: Where run/modal examples write: the earlier finished run's folder, a file, a folder below a
#: file, a folder that cannot be created (/proc refuses new entries, also to root).
OUTPUTS = ["finished", "file", "below_file", "uncreatable"]
#: Case paths that are not the written case file.
ODD_CASE_PATHS = ["missing", "folder", "devnull", "empty_name"]


@dataclass
class Example:
    """One command line to try: ``command``, the case (bytes written to a file, or an odd path),
    the options (``{case}``, ``{output}`` filled in by :meth:`argv`) and what was done."""

    command: str
    case_bytes: bytes | None
    case_path: str
    options: list[str]
    output: str | None
    as_json: bool
    done: list[str] = field(default_factory=list)

    def argv(self, case_file: Path, paths: dict[str, str]) -> list[str]:
        """The command line with this session's ``paths`` (of :data:`OUTPUTS` and
        :data:`ODD_CASE_PATHS`)."""
        case = str(case_file) if self.case_bytes is not None else paths[self.case_path]
        argv = [self.command, case, *self.options]
        if self.output is not None:
            argv += ["--output", paths[self.output], "--max-memory", RUN_MEMORY_LIMIT]
        return argv + (["--json"] if self.as_json else [])


#: The options each command takes a number for.
NUMERIC_OPTIONS = {
    "validate": [],
    "build": [],
    "run": ["--checkpoint-every", "--max-memory"],
    "modal": ["--modes", "--max-memory"],
}


@st.composite
def command_options(draw, command: str, raw: dict) -> list[str]:
    """1-2 mutated options: ``--set`` items, bad numbers (mostly for an option the command
    takes), unknown options, odd positionals, the progress flags."""
    options: list[str] = []
    for _ in range(draw(st.integers(1, 2))):
        kind = draw(st.sampled_from(["set", "set", "set", "number", "number", "unknown", "other"]))
        if kind == "set":
            item = draw(set_items(raw))
            options += draw(st.sampled_from([["--set", item], [f"--set={item}"]]))
        elif kind == "number":
            own = NUMERIC_OPTIONS[command]
            anyone = ["--checkpoint-every", "--max-memory", "--modes"]
            pool = own if own and draw(st.sampled_from([True, True, True, False])) else anyone
            options += [draw(st.sampled_from(pool)), draw(st.sampled_from(NUMBER_TEXTS))]
        elif kind == "unknown":
            options.append(draw(unknown_options))
        else:
            options.append(draw(st.sampled_from(["extra.yaml", "-", "--", "--progress", "--no-progress"])))
    return options


@st.composite
def examples(draw, bases: dict[str, dict], tiny: dict[str, dict]) -> Example:
    """A mutated case and/or command line: ``validate`` of any shipped case (most), ``validate
    --build`` of the tiny case, ``run`` and ``modal`` of the tiny case aimed at an output folder
    they must refuse (``run --restart`` of another case among them). Half the examples
    mutate the case only, a quarter the command line only, a quarter both; one in twenty names
    an odd case path."""
    command = draw(st.sampled_from(["validate", "validate", "validate", "run", "run", "modal", "build"]))
    pool = bases if command == "validate" else tiny
    name = draw(st.sampled_from(sorted(pool)))
    raw = pool[name]
    what = draw(st.sampled_from(["case", "case", "options", "both"]))
    if draw(st.sampled_from([False] * 19 + [True])):  # hypothesis favours the first of a list
        case_bytes, case_path, done = None, draw(st.sampled_from(ODD_CASE_PATHS)), [name]
    elif what == "options":
        case_bytes, case_path, done = dump(raw), "written", [name]
    else:
        case_bytes, mutations = draw(mutated_case(raw))
        case_path, done = "written", [name, *mutations]
    options = draw(command_options(command, raw)) if what != "case" else []
    output = draw(st.sampled_from(OUTPUTS)) if command in ("run", "modal") else None
    if output not in (None, "finished") and draw(st.sampled_from([False, False, False, True])):
        options.append(draw(st.sampled_from(["--overwrite", "--restart"])))
    if output == "finished" and command == "run" and draw(st.sampled_from([False, False, True])):
        options += ["--restart", *RESTART_CHANGE]  # the checkpoint of another case: refused
    if command == "build":
        command, options = "validate", ["--build", *options]
    done.append(" ".join(options))
    return Example(command, case_bytes, case_path, options, output, draw(st.booleans()), done)
