"""The caps on what a study may ask for, and how user data appears in a message.

Every cap is named in the refusal that enforces it, so a user who needs more knows what to change.
A message quotes a value of the study file only through `quoted`: a few dozen characters of text,
or the kind and size of a map or list, never the whole value (a value may be a YAML alias bomb)."""
import math

MAX_FILE_BYTES = 256 * 1024  # a study file's size [bytes]; the largest shipped one is ~8 kB
MAX_DEPTH = 12               # maps and lists inside each other
MAX_VALUES = 20000           # values of the file once its YAML aliases are expanded
MAX_TEXT = 4000              # characters of one text value (a description)
MAX_CHARACTERS = 400000      # characters of all text values once aliases are expanded
MAX_LIST = 1000              # values of one list (a sweep)
MAX_TASKS = 400000           # tasks one study may expand to (100 000 random carts × 4 integrators)
QUOTE_LENGTH = 40            # characters of a text value quoted in a message


class StudyError(ValueError):
    """A study file that cannot be run; the message names the file and the key."""


def quoted(value, length=QUOTE_LENGTH):
    """`value` as a message shows it: text in quotes cut to `length` characters with its control
    characters escaped, numbers as written, a map or list by its size only."""
    if isinstance(value, bool) or value is None:
        return {True: "true", False: "false", None: "null"}[value]
    if isinstance(value, int):
        return str(value) if abs(value) < 10 ** 30 else "a number of %d bits" % value.bit_length()
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        return repr(value) if math.isfinite(value) else ".inf" if value > 0 else "-.inf"
    if isinstance(value, str):
        text = "".join(_escaped(c) for c in value[:length])
        return "'%s'%s" % (text, "…" if len(value) > length else "")
    if isinstance(value, dict):
        return "a map of %d key%s" % (len(value), "" if len(value) == 1 else "s")
    if isinstance(value, (list, tuple)):
        return "a list of %d value%s" % (len(value), "" if len(value) == 1 else "s")
    return "a value of type %s" % type(value).__name__


def _escaped(character):
    if character == "'" or character == "\\":
        return "\\" + character
    return character if character.isprintable() else character.encode("unicode_escape").decode("ascii")


def refusal(path, parts, message):
    """The one line a refusal says: "study FILE: key 'experiments[1].runs.rk2': MESSAGE" (without
    the key when the problem is the file's top level)."""
    where = " key '%s':" % key_path(parts) if parts else ""
    return StudyError("study %s:%s %s" % (path, where, message))


def key_path(parts):
    """A key path as messages write it: experiments[1].runs.rk2 (names quoted only through `quoted`)."""
    text = ""
    for part in parts:
        if isinstance(part, int):
            text += "[%d]" % part
        else:
            name = part if isinstance(part, str) and part.isidentifier() and len(part) <= 64 else quoted(part)
            text += ("." if text else "") + name
    return text or "(the file)"
