"""pneufem.Scene: a scene file plus key = value overrides, resolved and checked as the CLI does."""
import copy
import json
import math
import os

from . import _core


def toml_value(value):
    """A Python value as TOML text for an override (the CLI's --set key=value syntax)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise _core.InputError(f"value {value!r}: scene values must be finite numbers")
        text = repr(value)
        return text if any(c in text for c in ".en") else text + ".0"
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string: JSON's escapes are TOML's
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return toml_value(value.tolist())
    raise _core.InputError(f"value {value!r} of type {type(value).__name__}: a scene value is a bool, int, float, "
                           "str or a list of them")


class Scene:
    """A scene: a TOML file ("" = the built-in default pneu-net) and overrides applied in order.

    Every change is checked at once (the same readers and messages as the commands): a bad key or
    value raises pneufem.InputError and leaves the scene as it was.
    """

    def __init__(self, path="", sets=()):
        self._path = os.fspath(path) if path else ""
        self._sets = list(sets)
        self._resolve()

    @classmethod
    def defaults(cls):
        """The built-in default scene (`pneufem scene --defaults`)."""
        return cls("")

    @classmethod
    def load(cls, path, sets=()):
        """A scene file, with optional overrides ("key=value" strings, as --set)."""
        return cls(path, sets)

    def _resolve(self):
        text_json, self._toml = _core.resolve_scene(self._path, self._sets)
        self._dict = json.loads(text_json)

    def set(self, key, value):
        """Sets a dotted key (e.g. "load.trials") to a Python value; returns the scene (chainable)."""
        old = self._sets
        self._sets = old + [f"{key}={toml_value(value)}"]
        try:
            self._resolve()
        except Exception:
            self._sets = old
            raise
        return self

    def update(self, values=None, **kwargs):
        """Sets several keys: a dict of dotted keys to values."""
        for k, v in dict(values or {}, **kwargs).items():
            self.set(k, v)
        return self

    def copy(self):
        return Scene(self._path, self._sets)

    def __getitem__(self, key):
        node = self._dict
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                raise KeyError(f"scene key '{key}' is not in the resolved scene (see pneufem scene --reference)")
            node = node[part]
        return copy.deepcopy(node)

    def __setitem__(self, key, value):
        self.set(key, value)

    def __contains__(self, key):
        try:
            self[key]
            return True
        except KeyError:
            return False

    def get(self, key, default=None):
        try:
            return self[key]
        except KeyError:
            return default

    def to_dict(self):
        """The resolved scene as nested dicts (what summary.json records under "scene")."""
        return copy.deepcopy(self._dict)

    def to_toml(self):
        """The resolved scene as TOML (what a run's scene.toml holds)."""
        return self._toml

    @property
    def path(self):
        """The scene file ("" = the built-in default)."""
        return self._path

    @property
    def sets(self):
        """The overrides, as the CLI's --set values."""
        return list(self._sets)

    def cli_args(self):
        """The scene as command-line arguments: [path] --set k=v ..."""
        args = [self._path] if self._path else []
        for s in self._sets:
            args += ["--set", s]
        return args

    def __eq__(self, other):
        return isinstance(other, Scene) and self._toml == other._toml

    def __repr__(self):
        src = self._path or "default"
        return f"pneufem.Scene({src!r}, {len(self._sets)} override(s))"
