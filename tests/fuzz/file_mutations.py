"""Seeded random mutations of the files peridyn reads: bytes (flips, truncation, zeroed and
repeated runs), Peridigm XML decks (parameters deleted, repeated, retyped, set to extreme or
garbage values), text meshes (wrong column counts, NaN, duplicate points) and expressions
(random trees of the expression language with odd leaves).

Each function takes a ``random.Random`` and returns the mutated value and a description of what
was done: an example is reproduced from its seed.
"""

from __future__ import annotations

import random
import xml.etree.ElementTree as ET

import h5py
import numpy as np
from fuzz_mutations import EXTREME_NUMBERS, GARBAGE_STRINGS, alias_bomb, paths

# ---------------------------------------------------------------------------- bytes

#: Byte strings spliced into a file: NUL, non-UTF-8, an XML entity and a YAML alias bomb, a
#: 2 GiB length field (big-endian, as netCDF-3 stores its counts).
SPLICES = [
    b"\x00",
    b"\xff\xfe",
    b"\xc0\xaf",
    b'<!DOCTYPE d [<!ENTITY a "aaaaaaaaaa">]>',
    b"&a;&a;&a;",
    alias_bomb(8),
    b"\x7f\xff\xff\xff",
    b"\xff\xff\xff\xff\xff\xff\xff\xff",
]


def mutate_bytes(
    data: bytes, rng: random.Random, live: list[tuple[int, int]] | None = None
) -> tuple[bytes, str]:
    """``data`` with one mutation: bits flipped, bytes set at random, cut short, a run zeroed,
    repeated or removed, or a splice from :data:`SPLICES`. With ``live`` (byte ranges
    ``[start, stop)`` that hold values, e.g. an HDF5 file's datasets), half the changes land in
    one of them."""
    n = len(data)
    if n == 0:
        return rng.choice(SPLICES), "a splice into an empty file"

    def offset() -> int:
        if live and rng.random() < 0.5:
            start, stop = rng.choice(live)
            return rng.randrange(start, max(start + 1, min(stop, n)))
        if rng.random() < 0.3:  # the head: headers, superblocks, dimensions
            return rng.randrange(min(n, 4096))
        return rng.randrange(n)

    kind = rng.choice(["flip", "flip", "flip", "bytes", "truncate", "zero", "repeat", "remove", "splice"])
    out = bytearray(data)
    if kind == "flip":
        at, bit = offset(), rng.randrange(8)
        out[at] ^= 1 << bit
        return bytes(out), f"bit {bit} of byte {at} flipped"
    if kind == "bytes":
        spots = sorted(offset() for _ in range(rng.randint(2, 8)))
        for at in spots:
            out[at] = rng.randrange(256)
        return bytes(out), f"bytes {spots} set at random"
    if kind == "truncate":
        at = rng.choice([0, 1, rng.randrange(n), n - 1, rng.randrange(min(n, 4096))])
        return data[:at], f"cut at byte {at} of {n}"
    start = offset()
    length = rng.choice([1, 4, 8, 64, 512, 4096])
    if kind == "zero":
        out[start : start + length] = bytes(len(out[start : start + length]))
        return bytes(out), f"{length} bytes zeroed at {start}"
    if kind == "repeat":
        return data[:start] + data[start : start + length] * 2 + data[start + length :], (
            f"{length} bytes at {start} repeated"
        )
    if kind == "remove":
        return data[:start] + data[start + length :], f"{length} bytes removed at {start}"
    splice = rng.choice(SPLICES)
    return data[:start] + splice + data[start:], f"{splice[:20]!r} spliced at {start}"


def hdf5_live_ranges(path) -> list[tuple[int, int]]:
    """Byte ranges ``[start, stop)`` of the values of every dataset of the HDF5 file ``path``
    (contiguous storage, or the rows written of its chunks)."""
    ranges: list[tuple[int, int]] = []

    def visit(_, obj):
        if not isinstance(obj, h5py.Dataset) or obj.id.get_storage_size() == 0:
            return
        if obj.chunks is None:
            offset = obj.id.get_offset()
            if offset is not None:
                ranges.append((offset, offset + obj.id.get_storage_size()))
            return
        used = obj.size * obj.dtype.itemsize
        for i in range(obj.id.get_num_chunks()):
            info = obj.id.get_chunk_info(i)
            ranges.append((info.byte_offset, info.byte_offset + max(1, min(info.size, used))))

    with h5py.File(path, "r") as f:
        f.visititems(visit)
    return ranges


# ---------------------------------------------------------------------------- Peridigm XML decks

#: Values a parameter's value is set to (numbers as Peridigm's text, garbage, expressions).
DECK_VALUES = [
    *(repr(v) for v in EXTREME_NUMBERS),
    "nan",
    "inf",
    "-inf",
    "1e999",
    "true",
    "TRUE",
    "maybe",
    "0.001*y*t/1.0e-8",
    "9**9**9",
    "x/0",
    "sqrt(-1)",
    "t*" * 300 + "t",
    "does_not_exist.g",
    "/dev/zero",
    *GARBAGE_STRINGS,
]
#: Parameter types: Peridigm's, and ones that are not.
DECK_TYPES = ["string", "double", "int", "bool", "float", "", "Array(double)"]


def mutate_xml_deck(text: str, rng: random.Random) -> tuple[bytes, str]:
    """The XML deck ``text`` with 1-3 mutations of its ``<Parameter>`` and ``<ParameterList>``
    elements (value, type, name, deleted, repeated, moved to the root), or as bytes
    (:func:`mutate_bytes`)."""
    if rng.random() < 0.25:
        return mutate_bytes(text.encode(), rng)
    root = ET.fromstring(text)
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        parents = [(p, c) for p in root.iter() for c in p]
        if not parents:
            break
        parent, child = rng.choice(parents)
        name = child.get("name", "")
        kind = rng.choice(["value", "value", "value", "type", "name", "delete", "repeat", "root"])
        if kind == "value" and child.tag == "Parameter":
            child.set("value", rng.choice(DECK_VALUES))
        elif kind == "type" and child.tag == "Parameter":
            child.set("type", rng.choice(DECK_TYPES))
        elif kind == "name":
            child.set(
                "name", rng.choice([name.lower(), name + " ", name[:-1], "", rng.choice(GARBAGE_STRINGS)])
            )
        elif kind == "delete":
            parent.remove(child)
        elif kind == "repeat":
            copy = ET.fromstring(ET.tostring(child))
            if copy.tag == "Parameter" and rng.random() < 0.5:
                copy.set("value", rng.choice(DECK_VALUES))
            parent.append(copy)
        else:
            kind = "root"
            parent.remove(child)
            root.append(child)
        done.append(f"{kind} {name!r}: {child.attrib.get('value', '')!r:.40}")
    return ET.tostring(root, encoding="utf-8"), "; ".join(done)


# ---------------------------------------------------------------------------- text meshes


def text_mesh(rng: random.Random, dim: int) -> str:
    """A valid text mesh (``x y z block volume`` lines) of a small grid of ``dim`` (2: at z = 0)."""
    nx, ny, nz = rng.randint(1, 6), rng.randint(1, 6), rng.randint(1, 3) if dim == 3 else 1
    h = 10.0 ** rng.uniform(-4, -1)
    lines = ["# x y z block volume"]
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                lines.append(f"{i * h:.9g} {j * h:.9g} {k * h:.9g} {1 + (i * 2 >= nx)} {h**3:.9g}")
    return "\n".join(lines) + "\n"


#: Tokens a mesh value is replaced by.
MESH_TOKENS = [
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e999",
    "-1",
    "0",
    "1.5",
    "x",
    "",
    "1,5",
    "0x10",
    "--1",
    "1e-400",
]


def mutate_text_mesh(text: str, rng: random.Random) -> tuple[bytes, str]:
    """The mesh ``text`` with one mutation: a value replaced (:data:`MESH_TOKENS`), a column
    added or removed, a point repeated, blank and comment lines, or as bytes."""
    lines = text.splitlines()
    data = [i for i, line in enumerate(lines) if line and not line.startswith("#")]
    kind = rng.choice(["token", "token", "columns", "duplicate", "comment", "bytes", "empty"])
    i = rng.choice(data)
    cols = lines[i].split()
    if kind == "token":
        c = rng.randrange(len(cols))
        cols[c] = rng.choice(MESH_TOKENS)
        lines[i] = " ".join(cols)
        return ("\n".join(lines) + "\n").encode(), f"line {i + 1} column {c + 1} = {cols[c]!r}"
    if kind == "columns":
        lines[i] = " ".join(cols[:-1] if rng.random() < 0.5 else [*cols, "1.0"])
        return ("\n".join(lines) + "\n").encode(), f"line {i + 1} with {len(lines[i].split())} columns"
    if kind == "duplicate":
        lines.insert(i, lines[i])
        return ("\n".join(lines) + "\n").encode(), f"line {i + 1} twice"
    if kind == "comment":
        lines.insert(i, rng.choice(["", "   ", "# note", "#", "\t", "; not a comment"]))
        return ("\n".join(lines) + "\n").encode(), f"a line inserted before {i + 1}"
    if kind == "empty":
        return rng.choice([b"", b"\n", b"# only a comment\n", b"\x00" * 16]), "no points"
    return mutate_bytes(text.encode(), rng)


# ---------------------------------------------------------------------------- expressions

#: Leaves of a random expression: numbers (extreme ones too), names known and unknown,
#: indexing, and text that is not of the language.
LEAVES = [
    "1",
    "0",
    "2.5",
    "1e308",
    "1e-320",
    "9",
    "99",
    "-1",
    "x",
    "t",
    "size[0]",
    "size[5]",
    "size[-1]",
    "size[1.5]",
    "unknown",
    "__import__",
    "().__class__",
    "'text'",
    "[1, 2]",
    "lambda: 1",
    "f'{1}'",
    "True",
    "None",
]
#: Binary operators and functions of the language, and some that are not.
OPERATORS = ["+", "-", "*", "/", "**", "//", "%", "@", "<", "and", "|"]
FUNCTIONS = ["min", "max", "abs", "sqrt", "round", "sin", "cos", "exp", "log", "open", "eval", "len"]


def expression(rng: random.Random, depth: int = 0) -> str:
    """A random expression of up to 4 levels (one in ten an odd text: deep nesting, very long,
    unbalanced, or a power tower)."""
    if depth == 0 and rng.random() < 0.1:
        return rng.choice(
            [
                "(" * 5000 + "1" + ")" * 5000,
                "1+" * 1500 + "1",
                "-" * 3000 + "1",
                "9**9**9",
                "10**10**10",
                "2**" * 50 + "2",
                "(1+",
                "",
                " ",
                "\x00",
                "1 if 1 else 2",
                "[x for x in size]",
                "size.__class__",
            ]
        )
    if depth >= 4 or rng.random() < 0.3:
        return rng.choice(LEAVES)
    kind = rng.random()
    if kind < 0.5:
        op = rng.choice(OPERATORS)
        return f"({expression(rng, depth + 1)} {op} {expression(rng, depth + 1)})"
    if kind < 0.7:
        return f"-{expression(rng, depth + 1)}"
    name = rng.choice(FUNCTIONS)
    args = ", ".join(expression(rng, depth + 1) for _ in range(rng.choice([0, 1, 1, 2, 3])))
    return f"{name}({args})"


def expression_names(rng: random.Random) -> dict:
    """Values of the names an expression may use: scalars or arrays (of x and t), lists."""
    n = rng.choice([1, 3, 100])
    return {
        "x": rng.choice([0.5, np.linspace(-1.0, 1.0, n), np.zeros(n)]),
        "t": rng.choice([0.0, 1.0e-6, -1.0]),
        "size": rng.choice([[0.1, 0.02], [0.0], []]),
    }


# ---------------------------------------------------------------------------- YAML mappings

#: Values an entry of a mapping is set to.
MAPPING_VALUES = [*EXTREME_NUMBERS, *GARBAGE_STRINGS[:-1], None, True, [], {}, [1, 2], {"a": 1}, "9**9**9"]


def mutate_mapping(raw: dict, rng: random.Random) -> str:
    """Change the nested mapping ``raw`` in place with 1-2 mutations (an entry deleted, renamed
    with a typo, set to an extreme or garbage value, emptied, or a key invented); returns what
    was done."""
    done = []
    for _ in range(rng.choice([1, 1, 2])):
        where = paths(raw)
        if not where:
            raw[rng.choice(GARBAGE_STRINGS)] = rng.choice(MAPPING_VALUES)
            done.append("invent at the root")
            continue
        path = rng.choice(where)
        parent = raw
        for part in path[:-1]:
            parent = parent[part]
        key = path[-1]
        kind = rng.choice(["delete", "rename", "value", "value", "empty", "invent"])
        if kind == "delete":
            del parent[key]
        elif kind == "rename" and isinstance(parent, dict):
            text = str(key)
            i = rng.randrange(max(1, len(text)))
            parent[text[:i] + text[i + 1 :] or "x"] = parent.pop(key)
        elif kind == "invent" and isinstance(parent, dict):
            parent[f"{key}_"] = rng.choice(MAPPING_VALUES)
        elif kind == "empty":
            parent[key] = rng.choice([[], {}, None, ""])
        else:
            kind = "value"
            parent[key] = rng.choice(MAPPING_VALUES)
        done.append(f"{kind} {'.'.join(map(str, path))}")
    return "; ".join(done)
