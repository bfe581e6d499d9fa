"""YAML files as people write them: read strictly, updated without losing what they wrote.

Every YAML file robotcell reads (cell files, robot model files, layouts files) goes through
:func:`parse_yaml`, which uses the round-trip mode of ruamel.yaml:

- **Duplicate keys are refused.** YAML keeps only the last of two equal keys in a mapping, so a
  cell file with two ``tools:`` sections would silently lose the first. The error names the key
  and its line.
- **Nesting is bounded** at :data:`MAX_DEPTH` levels (a valid file needs at most 5). The events
  of the file are counted before anything is built from them, so a file nested thousands of
  levels deep is refused at once, naming the line where it passes the bound, instead of
  exhausting the interpreter's recursion.
- **What the user wrote is kept.** The parsed document remembers comments, key order, flow or
  block style and the spelling of every value; :func:`update_document` changes in place only
  the values that a program changed, and :func:`dump_yaml` writes the rest exactly as it was.

Every YAML file robotcell writes (cell files, robot model files) is made by :func:`dump_yaml`,
which reads its text back before returning it: a text that does not parse, or parses to other
data than was given, is never returned (:class:`~robotcell.errors.RobotcellError`), so it never
replaces a file. A collection is written on one line (flow style: poses, rows of numbers) only
when it holds no other collection and fits in :data:`FLOW_MAX` characters; a longer one, or one
that holds collections (the provenance of a calibrated item with its error sources), is written
one entry a line (block style), also where the file had it in flow style. No line of a mapping
is then ever broken by the writer, which YAML does not allow inside a key (``track 45f77e8b0e19``
is a key of an item's error sources).
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq
from ruamel.yaml.constructor import DuplicateKeyError
from ruamel.yaml.error import MarkedYAMLError, YAMLError
from ruamel.yaml.events import CollectionEndEvent, CollectionStartEvent

from robotcell.errors import InputError, RobotcellError

__all__ = ["FLOW_MAX", "MAX_DEPTH", "dump_yaml", "parse_yaml", "update_document", "written_yaml"]

#: Deepest nesting of mappings and lists accepted. A cell file needs 4 (``tools`` > name >
#: ``frame`` > ``x``), a robot model file 5 (a coupling matrix in a nested ``ik_seed``).
MAX_DEPTH = 32

#: Longest collection written on one line (characters, estimated): far below the writer's line
#: width (4096), so that a flow collection is never broken over lines.
FLOW_MAX = 1000


def _yaml() -> YAML:
    y = YAML(typ="rt", pure=True)
    y.width = 4096  # a flow mapping (a pose) stays on its line
    y.indent(mapping=2, sequence=4, offset=2)
    return y


def _where(err: YAMLError) -> str:
    """``line L, column C: `` of a YAML error, or nothing when it has no position."""
    mark = (err.problem_mark or err.context_mark) if isinstance(err, MarkedYAMLError) else None
    return f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""


def _check_depth(yaml: YAML, text: str, origin: str) -> None:
    depth = 0
    for event in yaml.parse(text):
        if isinstance(event, CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise InputError(
                    f"{origin}: line {event.start_mark.line + 1}: nested more than {MAX_DEPTH} "
                    "levels deep; no valid file needs that many: check the indentation and the "
                    "brackets")
        elif isinstance(event, CollectionEndEvent):
            depth -= 1


def parse_yaml(text: str, origin: str) -> Any:
    """Parse YAML text, keeping comments and layout; refuse duplicate keys and deep nesting.

    Parameters
    ----------
    text : str
        The file's content.
    origin : str
        What to call the source in error messages (a file name).

    Returns
    -------
    Any
        Mappings are ``dict`` subclasses and lists ``list`` subclasses that remember comments,
        key order and style (ruamel.yaml's round-trip types); ``None`` for an empty text.

    Raises
    ------
    InputError
        Invalid YAML, a key given twice in one mapping, or nesting deeper than
        :data:`MAX_DEPTH`; the message names the line.
    """
    yaml = _yaml()
    try:
        _check_depth(yaml, text, origin)
        return yaml.load(text)
    except DuplicateKeyError as exc:
        key = str(exc.problem).split('"')[1] if '"' in str(exc.problem) else "?"
        raise InputError(
            f"{origin}: {_where(exc)}key {key!r} is given twice in the same mapping (YAML would "
            "keep only the last one); merge the two or remove one") from None
    except YAMLError as exc:
        problem = getattr(exc, "problem", None) or str(exc)
        raise InputError(f"{origin}: not valid YAML: {_where(exc)}{problem}") from None


def dump_yaml(data: Any, what: str = "the file") -> str:
    """YAML text of ``data``: a document from :func:`parse_yaml` as it was written.

    Plain mappings and lists are written in block style, with the innermost ones (poses, short
    lists of numbers) in flow style. The text is read back before it is returned
    (:func:`written_yaml`).

    Parameters
    ----------
    data : Any
        Mappings, lists and scalars, plain or as returned by :func:`parse_yaml`; a collection in
        flow style that holds collections or is longer than :data:`FLOW_MAX` is set to block
        style.
    what : str
        What is written, for the message of a text that does not read back.

    Returns
    -------
    str
        Text that :func:`parse_yaml` reads to data equal to ``data``.

    Raises
    ------
    RobotcellError
        The text would not read back as ``data`` (a defect of the writer: nothing is written).
    """
    return written_yaml(data, what)[0]


def written_yaml(data: Any, what: str = "the file") -> tuple[str, Any]:
    """:func:`dump_yaml` of ``data`` and the document its text reads back as.

    Parameters
    ----------
    data : Any
        As for :func:`dump_yaml`.
    what : str
        What is written, for the message of a text that does not read back.

    Returns
    -------
    text : str
    document : Any
        :func:`parse_yaml` of ``text``, equal to ``data``.

    Raises
    ------
    RobotcellError
        The text would not read back as ``data`` (a defect of the writer: nothing is written).
    """
    styled = _styled(data)
    _restyle(styled)
    buf = io.StringIO()
    _yaml().dump(styled, buf)
    text = buf.getvalue()
    back = None
    try:
        back = parse_yaml(text, what)
    except InputError as exc:
        why: str | None = str(exc)
    else:
        why = _difference(_plain(back), _plain(data))
    if why:
        raise RobotcellError(f"the YAML text written for {what} does not read back as what was "
                             f"meant ({why}); nothing was written. This is a defect of "
                             "robotcell: please report it with the file")
    return text, back


def _plain(value: Any) -> Any:
    """``value`` as plain dicts, lists and scalars (tuples as lists)."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _difference(got: Any, meant: Any, where: str = "") -> str | None:
    """Where plain data ``got`` differs from ``meant`` (NaN equal to NaN), or None."""
    at = where or "the top level"
    if isinstance(meant, dict) or isinstance(got, dict):
        if not (isinstance(meant, dict) and isinstance(got, dict)) or list(got) != list(meant):
            return f"the keys at {at}"
        for key in meant:
            why = _difference(got[key], meant[key], f"{where}.{key}" if where else str(key))
            if why:
                return why
        return None
    if isinstance(meant, list) or isinstance(got, list):
        if not (isinstance(meant, list) and isinstance(got, list)) or len(got) != len(meant):
            return f"the list at {at}"
        for i, (g, m) in enumerate(zip(got, meant)):
            why = _difference(g, m, f"{where}[{i}]")
            if why:
                return why
        return None
    same = got == meant or (isinstance(got, float) and isinstance(meant, float)
                            and math.isnan(got) and math.isnan(meant))
    return None if same else f"the value at {at}"


def _is_leaf(value: Any) -> bool:
    items = value.values() if isinstance(value, Mapping) else value
    return not any(isinstance(v, (Mapping, list)) for v in items)


def _flow_length(value: Any) -> int:
    """Length of ``value`` (a leaf collection) written on one line, over-estimated."""
    parts = [*value.keys(), *value.values()] if isinstance(value, Mapping) else list(value)
    return 2 + sum(len(repr(v)) + 4 for v in parts)


def _one_line(value: Any) -> bool:
    """Whether a collection is written in flow style: a leaf of at most :data:`FLOW_MAX`."""
    return bool(value) and _is_leaf(value) and _flow_length(value) <= FLOW_MAX


def _styled(value: Any) -> Any:
    """``value`` as round-trip types: innermost collections in flow style, as written by hand."""
    if isinstance(value, (CommentedMap, CommentedSeq)):
        return value
    if isinstance(value, Mapping):
        out: Any = CommentedMap((k, _styled(v)) for k, v in value.items())
    elif isinstance(value, (list, tuple)):
        out = CommentedSeq(_styled(v) for v in value)
    else:
        return value
    if _one_line(out):
        out.fa.set_flow_style()
    return out


def _restyle(value: Any) -> None:
    """Set to block style every flow collection in ``value`` that :func:`_one_line` refuses."""
    if not isinstance(value, (CommentedMap, CommentedSeq)):
        return
    if value.fa.flow_style() and not _one_line(value):
        value.fa.set_block_style()
    for item in value.values() if isinstance(value, CommentedMap) else value:
        _restyle(item)


def update_document(doc: CommentedMap, old: Mapping[str, Any], new: Mapping[str, Any]) -> None:
    """Make ``doc`` say what ``new`` says, changing only what differs from ``old``, in place.

    A three-way merge: ``doc`` is the file as the user wrote it, ``old`` what a program reads it
    to (in the program's own spelling) and ``new`` what the program wants it to say now. A value
    equal in ``old`` and ``new`` stays as written (``1500.0`` is not rewritten as ``1500``); a
    changed value replaces the written one in its place, keeping the comment beside it; a key of
    ``new`` only is inserted after the key that precedes it in ``new``; a key of ``old`` that
    ``new`` drops is removed. Keys the program never wrote (in ``doc`` only) are kept. Lists of
    the same length are merged item by item, others replaced whole.

    Parameters
    ----------
    doc : mapping from :func:`parse_yaml`
        Updated in place.
    old, new : mapping
        Plain content before and after the change.
    """
    for key in [k for k in doc if k in old and k not in new]:
        del doc[key]
    previous = None
    for key, value in new.items():
        if key not in doc:
            at = list(doc).index(previous) + 1 if previous in doc else len(doc)
            doc.insert(at, key, _styled(value))
        elif key not in old or old[key] != value:
            doc[key] = _merged(doc[key], old.get(key), value)
        previous = key


def _merged(written: Any, old: Any, new: Any) -> Any:
    """The value to put where ``written`` stands so that it says ``new``."""
    if isinstance(written, CommentedMap) and isinstance(new, Mapping):
        update_document(written, old if isinstance(old, Mapping) else {}, new)
        return written
    if (isinstance(written, CommentedSeq) and isinstance(new, (list, tuple))
            and len(written) == len(new)):
        olds = old if isinstance(old, list) and len(old) == len(new) else [None] * len(new)
        for i, (w, o, n) in enumerate(zip(written, olds, new)):
            if o is None or o != n:
                written[i] = _merged(w, o, n)
        return written
    return _styled(new)
