"""Python values as RON text, the language of Luxon's scene files: what lets every method
take keyword arguments (``position=(0, 0, 5)``) as well as the RON text itself."""

import math
import os


class Ron:
    """RON text used as it is: ``Ron("Exp(density: 0.05)")``."""

    __slots__ = ("text",)

    def __init__(self, text):
        self.text = str(text)

    def __repr__(self):
        return f"Ron({self.text!r})"


class Variant:
    """An enum variant of RON: ``Variant("Exp", density=0.05)`` is ``Exp(density: 0.05)``;
    ``Variant("Off")`` is ``Off``."""

    __slots__ = ("name", "fields")

    def __init__(self, name, **fields):
        self.name = name
        self.fields = fields

    def __repr__(self):
        return f"Variant({to_ron(self)})"


def _string(s):
    out = ['"']
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or 0x7F <= ord(ch) < 0xA0:
            out.append("\\u{%x}" % ord(ch))
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _fields(d):
    parts = []
    for k, v in d.items():
        if not (isinstance(k, str) and k.isidentifier()):
            raise TypeError(f"field name {k!r}: expected an identifier")
        parts.append(f"{k}: {to_ron(v)}")
    return ", ".join(parts)


def to_ron(value):
    """``value`` as RON: tuples and 1-D arrays as ``(a, b, c)``, lists and 2-D arrays as
    ``[...]``, dicts as structs ``(key: value)``, strings and paths quoted, None as ``None``,
    :class:`Ron` as its text and :class:`Variant` as ``Name(field: value)``."""
    if isinstance(value, Ron):
        return value.text
    if isinstance(value, Variant):
        return f"{value.name}({_fields(value.fields)})" if value.fields else value.name
    if value is None:
        return "None"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(int(value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{value}: RON numbers must be finite")
        # float(): numpy's float64 is a float whose repr is "np.float64(...)".
        return repr(float(value))
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, os.PathLike):
        return _string(os.fspath(value))
    if isinstance(value, dict):
        return f"({_fields(value)})"
    if isinstance(value, tuple):
        return "(" + ", ".join(to_ron(v) for v in value) + ")"
    if isinstance(value, list):
        return "[" + ", ".join(to_ron(v) for v in value) + "]"
    # numpy arrays and scalars, without importing numpy here.
    if hasattr(value, "tolist") and hasattr(value, "ndim"):
        items = value.tolist()
        if value.ndim == 0:
            return to_ron(items)
        if value.ndim == 1:
            return to_ron(tuple(items))
        return to_ron([tuple(r) if isinstance(r, list) else r for r in items])
    raise TypeError(f"{type(value).__name__} {value!r} cannot be written as RON")


def text(ron, fields, what):
    """The RON text of a call that takes either text or keyword fields (a struct)."""
    if ron is not None and fields:
        raise TypeError(f"{what}: give RON text or keyword arguments, not both")
    if ron is not None:
        if not isinstance(ron, str):
            raise TypeError(f"{what}: RON text must be a str, not {type(ron).__name__}")
        return ron
    return f"({_fields(fields)})"
