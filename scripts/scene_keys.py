#!/usr/bin/env python3
"""The scene keys declared in core/scene/keys.yaml: lookup, defaults and checks for the Python
tools, the C++ header the build compiles, and the reference page docs/scene-keys.md.

  scripts/scene_keys.py --write           rewrite docs/scene-keys.md
  scripts/scene_keys.py --check           exit 1 when docs/scene-keys.md is not what --write would write
  scripts/scene_keys.py --cpp OUT.hpp     write the C++ table and default constants (the build runs it)

In Python: `declared(path)`, `default(path)` and `check_map(value, path, scene_path, error)`; a path
is dotted with list indices, e.g. "artery.layers.media.fibers[0].k1". Units: mm, N, MPa, s.
"""
import argparse
import difflib
import math
import re
import sys
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
KEYS_FILE = ROOT / "core" / "scene" / "keys.yaml"
REFERENCE = ROOT / "docs" / "scene-keys.md"
TYPES = ("number", "integer", "boolean", "string", "point", "numbers", "map", "list", "any")
FIELDS = ("type", "unit", "default", "default_text", "range", "values", "doc", "optional", "peak")
INTERVAL = re.compile(r"^([\[(])\s*(-?inf|[-+0-9.eE]+)\s*,\s*(-?inf|[-+0-9.eE]+)\s*([\])])$")
INT_MAX = 2**31 - 1


class KeysFileError(Exception):
    """keys.yaml itself is malformed (a programming error, not a user's)."""


@dataclass
class Interval:
    lo: float
    hi: float
    lo_open: bool
    hi_open: bool

    def __contains__(self, v):
        above = v > self.lo if self.lo_open else v >= self.lo
        below = v < self.hi if self.hi_open else v <= self.hi
        return above and below


@dataclass
class Decl:
    path: str
    types: tuple
    doc: str
    unit: str = ""
    default: object = None
    has_default: bool = False
    default_text: str = ""
    range: Interval = None
    range_text: str = ""
    values: tuple = ()
    optional: bool = False
    peak: tuple = None  # (max, why): the plausible peak of a {value, curve} load, in the key's unit
    segments: tuple = field(default=(), repr=False)

    @property
    def required(self):
        return not (self.has_default or self.default_text or self.optional)


def _interval(text, where):
    m = INTERVAL.match(str(text).strip())
    if not m:
        raise KeysFileError(f"{KEYS_FILE}: {where}.range: expected an interval like '[0, inf)', got {text!r}")
    return Interval(float(m.group(2)), float(m.group(3)), m.group(1) == "(", m.group(4) == ")")


def _decl(path, spec):
    where = f"{KEYS_FILE}: {path}"
    if not isinstance(spec, dict) or "type" not in spec or "doc" not in spec:
        raise KeysFileError(f"{where}: expected a map with at least `type` and `doc`")
    for k in spec:
        if k not in FIELDS:
            raise KeysFileError(f"{where}.{k}: unknown field, expected one of {', '.join(FIELDS)}")
    types = tuple(spec["type"]) if isinstance(spec["type"], list) else (spec["type"],)
    for t in types:
        if t not in TYPES:
            raise KeysFileError(f"{where}.type: expected one of {', '.join(TYPES)}, got {t!r}")
    d = Decl(
        path=path,
        types=types,
        doc=str(spec["doc"]),
        unit=str(spec.get("unit", "")),
        default=spec.get("default"),
        has_default="default" in spec,
        default_text=str(spec.get("default_text", "")),
        range_text=str(spec.get("range", "")),
        values=tuple(str(v) for v in spec.get("values", ())),
        optional=bool(spec.get("optional", False)),
        segments=tuple(path.split(".")),
    )
    if "range" in spec:
        d.range = _interval(spec["range"], path)
    if "peak" in spec:
        pk = spec["peak"]
        if not (isinstance(pk, dict) and set(pk) == {"max", "why"} and isinstance(pk["max"], (int, float))):
            raise KeysFileError(f"{where}.peak: expected {{max: a number, why: the reason}}, got {pk!r}")
        d.peak = (float(pk["max"]), str(pk["why"]))
    if d.has_default and d.default is not None and not _valid(d, d.default):
        raise KeysFileError(f"{where}.default: {d.default!r} is not {expected(d)}")
    return d


@lru_cache(maxsize=None)
def declarations():
    """{pattern: Decl} in the file's order."""
    with open(KEYS_FILE) as f:
        raw = yaml.safe_load(f)
    if not isinstance(raw, dict):
        raise KeysFileError(f"{KEYS_FILE}: expected a map of key paths")
    return {str(p): _decl(str(p), s) for p, s in raw.items()}


def _segments(path):
    return tuple(re.sub(r"\[\d+\]", "[]", path).split(".")) if path else ()


def _matches(pattern, segs):
    return len(pattern) == len(segs) and all(
        p == s or (p == "*" and not s.endswith("[]")) for p, s in zip(pattern, segs)
    )


def declared(path):
    """The declaration of a concrete key path (exact segments preferred over `*`), or None."""
    segs = _segments(path)
    hits = [d for d in declarations().values() if _matches(d.segments, segs)]
    return min(hits, key=lambda d: d.segments.count("*")) if hits else None


def default(path):
    d = declared(path)
    if d is None or not d.has_default:
        raise KeyError(f"{path}: not a declared key with a default")
    return d.default


def children(path):
    """The keys a map at `path` may hold; '*' when any name is allowed."""
    segs = _segments(path)
    out = []
    for d in declarations().values():
        if len(d.segments) == len(segs) + 1 and _matches(d.segments[:-1], segs):
            name = d.segments[-1].removesuffix("[]")
            if name not in out:
                out.append(name)
    return out


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _valid_as(d, t, v):
    if t == "number":
        return _is_number(v) and (d.range is None or v in d.range)
    if t == "integer":
        return isinstance(v, int) and not isinstance(v, bool) and (d.range is None or v in d.range)
    if t == "boolean":
        return isinstance(v, bool)
    if t == "string":
        return isinstance(v, str) and (not d.values or v in d.values)
    if t == "point":
        return isinstance(v, list) and len(v) == 3 and all(_is_number(x) for x in v)
    if t == "numbers":
        return isinstance(v, list) and all(_is_number(x) for x in v)
    if t == "map":
        return isinstance(v, dict)
    if t == "list":
        return isinstance(v, list)
    return True


def _valid(d, v):
    return any(_valid_as(d, t, v) for t in d.types)


def _fmt(x):
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:g}"


def expected(d):
    """What a value of the key must be, in the words of the C++ readers' messages."""
    parts = []
    for t in d.types:
        r = d.range
        if t == "number":
            if r is None or (math.isinf(r.lo) and math.isinf(r.hi)):
                s = "a number"
            elif r.lo == 0 and math.isinf(r.hi):
                s = "a positive number" if r.lo_open else "a non-negative number"
            else:
                s = f"a number in {'(' if r.lo_open else '['}{_fmt(r.lo)}, {_fmt(r.hi)}{')' if r.hi_open else ']'}"
        elif t == "integer":
            if r is None:
                s = "an integer"
            elif math.isinf(r.hi):
                s = f"an integer >= {int(r.lo)}"
            else:
                s = f"an integer in {int(r.lo)}..{int(r.hi)}"
        elif t == "string" and d.values:
            s = "one of " + ", ".join(d.values)
        else:
            s = {"boolean": "true or false", "point": "a point [x, y, z]", "numbers": "a list of numbers"}.get(
                t, f"a {t}"
            )
        parts.append(s)
    text = " or ".join(parts)
    if d.unit and d.unit != "1" and any(t in ("number", "integer", "point", "numbers") for t in d.types):
        text += f" ({d.unit})"
    return text


def check_map(value, path, scene_path, error):
    """The map at `path` with its declared keys checked and the absent ones' defaults filled in;
    `error(message)` is raised for an unknown key, a missing required one or a bad value."""
    if not isinstance(value, dict):
        raise error(f"{scene_path}: {path}: expected a map of keys ({', '.join(children(path))}), got {value!r:.60}")
    allowed = children(path)
    for k in value:
        if "*" not in allowed and str(k) not in allowed:
            near = difflib.get_close_matches(str(k), allowed, n=1)
            hint = f"; did you mean `{near[0]}`?" if near else ""
            raise error(f"{scene_path}: {path}.{k}: unknown key, expected one of {', '.join(allowed)}{hint}")
    out = {}
    for name in allowed:
        if name == "*":
            continue
        sub = declared(f"{path}.{name}")
        if name not in value:
            if sub.has_default:
                out[name] = sub.default
            elif sub.required:
                raise error(f"{scene_path}: {path}.{name}: missing, expected {expected(sub)}: {sub.doc}")
            else:
                out[name] = None
            continue
        v = value[name]
        if not _valid(sub, v):
            raise error(f"{scene_path}: {path}.{name}: expected {expected(sub)}, got {v!r:.60}")
        out[name] = v
    return out


# --------------------------------------------------------------------------------------------------
# the reference page


def _default_cell(d):
    if d.has_default:
        v = d.default
        if isinstance(v, bool):
            return "`true`" if v else "`false`"
        if isinstance(v, str):
            return f'`"{v}"`' if v == "" else f"`{v}`"
        if isinstance(v, list):
            return "`[" + ", ".join(str(x) for x in v) + "]`"
        return f"`{v:g}`" if isinstance(v, float) else f"`{v}`"
    if d.default_text:
        return d.default_text
    return "optional" if d.optional else "**required**"


def _range_cell(d):
    cells = []
    if d.range_text:
        cells.append(d.range_text.replace("inf", "∞"))
    if d.values:
        cells.append(" \\| ".join(f"`{v}`" for v in d.values))
    if d.peak:
        cells.append(f"peak ≤ {d.peak[0]:g} {d.unit} ({d.peak[1]})")
    return "; ".join(cells)


def reference_markdown():
    decls = list(declarations().values())
    lines = [
        "# Scene keys",
        "",
        "Generated from `core/scene/keys.yaml` by `scripts/scene_keys.py --write`; do not edit by hand (the",
        "test `scene_keys.reference` fails when this page is stale). Units: mm, N, MPa, s. `*` is any name (a",
        "layer, a load curve), `[]` every entry of a list. A key whose default is **required** must be given",
        "when its section is; *optional* means that absent it is off or not used.",
        "",
    ]
    section = None
    for d in decls:
        top = d.segments[0].removesuffix("[]")
        if top != section:
            section = top
            lines += [
                f"## `{top}`",
                "",
                "| key | type | unit | default | range / values | meaning |",
                "|---|---|---|---|---|---|",
            ]
        doc = d.doc.replace("|", "\\|")
        unit = "" if d.unit in ("", "1") else d.unit
        lines.append(
            f"| `{d.path}` | {' or '.join(d.types)} | {unit} | {_default_cell(d)} | {_range_cell(d)} | {doc} |"
        )
        nxt = decls.index(d) + 1
        if nxt == len(decls) or decls[nxt].segments[0].removesuffix("[]") != top:
            lines.append("")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------------
# the C++ header


def _cpp_string(s):
    return '"' + str(s).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _cpp_double(x):
    if math.isinf(x):
        return "kInf" if x > 0 else "-kInf"
    return repr(float(x))


def cpp_name(path):
    """The name of a key's default constant: coupling.rel_tol -> coupling_rel_tol (wildcards dropped)."""
    return re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9]", "_", path.replace("*", "").replace("[]", ""))).strip("_")


def cpp_header():
    rows, consts, peaks, names = [], [], [], set()
    for d in declarations().values():
        r = d.range or Interval(-math.inf, math.inf, False, False)
        dnum, dstr = 0.0, ""
        # list defaults (e.g. a point) are documented here and applied by their reader
        scalar_default = d.has_default and not isinstance(d.default, (list, dict)) and d.default is not None
        if scalar_default:
            if isinstance(d.default, str):
                dstr = d.default
            else:
                dnum = float(d.default)
        rows.append(
            "    {"
            + ", ".join(
                [
                    _cpp_string(d.path),
                    _cpp_string("|".join(d.types)),
                    _cpp_string(d.unit),
                    _cpp_string(d.doc),
                    "true" if scalar_default else "false",
                    _cpp_double(dnum),
                    _cpp_string(dstr),
                    _cpp_double(r.lo),
                    _cpp_double(r.hi),
                    "true" if r.lo_open else "false",
                    "true" if r.hi_open else "false",
                    _cpp_string("|".join(d.values)),
                    _cpp_string(expected(d)),
                ]
            )
            + "},"
        )
        if d.peak:
            peaks += [
                f"inline constexpr double {cpp_name(d.path)} = {_cpp_double(d.peak[0])};",
                f"inline constexpr const char* {cpp_name(d.path)}_why = {_cpp_string(d.peak[1])};",
            ]
        scalar = len(d.types) == 1 and d.types[0] in ("number", "integer", "boolean", "string")
        if d.has_default and scalar:
            name = cpp_name(d.path)
            if name in names:
                continue
            names.add(name)
            t = d.types[0]
            if t == "number":
                consts.append(f"inline constexpr double {name} = {_cpp_double(float(d.default))};")
            elif t == "integer":
                consts.append(f"inline constexpr int {name} = {int(d.default)};")
            elif t == "boolean":
                consts.append(f"inline constexpr bool {name} = {'true' if d.default else 'false'};")
            else:
                consts.append(f"inline constexpr const char* {name} = {_cpp_string(d.default)};")
    return "\n".join(
        [
            "// Generated from core/scene/keys.yaml by scripts/scene_keys.py --cpp; do not edit.",
            "#pragma once",
            "#include <cstddef>",
            "#include <limits>",
            "",
            "namespace angio::scene::keys {",
            "",
            "inline constexpr double kInf = std::numeric_limits<double>::infinity();",
            "",
            "// One declared key: its path pattern, types ('|'-separated), unit, meaning, scalar default (a",
            "// number, or a string for string keys), range [lo, hi] with open ends, allowed strings",
            "// ('|'-separated), and what a value must be in the words of an error message.",
            "struct Decl {",
            "  const char* path;",
            "  const char* type;",
            "  const char* unit;",
            "  const char* doc;",
            "  bool has_default;",
            "  double default_number;",
            "  const char* default_string;",
            "  double lo, hi;",
            "  bool lo_open, hi_open;",
            "  const char* values;",
            "  const char* expected;",
            "};",
            "",
            "inline constexpr Decl kTable[] = {",
            *rows,
            "};",
            "inline constexpr std::size_t kCount = sizeof(kTable) / sizeof(kTable[0]);",
            "",
            "// The defaults of the scalar keys, for the initializers of the structs the readers fill.",
            "namespace defaults {",
            *consts,
            "}  // namespace defaults",
            "",
            "// The plausible peaks (value x load curve, in the key's unit) of the loads that declare one, and why.",
            "namespace peaks {",
            *peaks,
            "}  // namespace peaks",
            "",
            "}  // namespace angio::scene::keys",
            "",
        ]
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--write", action="store_true", help=f"rewrite {REFERENCE.relative_to(ROOT)}")
    g.add_argument("--check", action="store_true", help=f"exit 1 when {REFERENCE.relative_to(ROOT)} is stale")
    g.add_argument("--cpp", metavar="OUT", help="write the C++ header")
    a = ap.parse_args(argv)
    try:
        if a.cpp:
            text = cpp_header()
            out = Path(a.cpp)
            if not out.exists() or out.read_text() != text:  # unchanged: keep the timestamp (no rebuild)
                out.parent.mkdir(parents=True, exist_ok=True)
                out.write_text(text)
            return 0
        text = reference_markdown()
        if a.write:
            REFERENCE.write_text(text)
            return 0
        if not REFERENCE.exists() or REFERENCE.read_text() != text:
            print(
                f"scene_keys: {REFERENCE.relative_to(ROOT)} is stale: run scripts/scene_keys.py --write",
                file=sys.stderr,
            )
            return 1
        return 0
    except KeysFileError as e:
        print(f"scene_keys: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
