"""Scene files (TOML) -> validated, immutable :class:`Scene`.

A scene may start from a preset (``preset = "NAME"``), or from a preset combined with parts such as a
regime (``preset = ["chain-S2", "regime-A"]``, merged in order), and override keys: tables merge key by
key, arrays of tables are replaced whole.  ``solver.options`` belong to ``solver.method``: a layer that names
another method without options of its own drops the options below it.
"""
from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import tomli_w

from cvtfem.errors import InputError
from cvtfem.scene.node import Node, thaw
from cvtfem.scene.schema import SCENE, scene_kind
from cvtfem.scene.schema.base import Key, Table, validate

PRESET_PACKAGE = "cvtfem.scene.presets"
#: Sub-folder of the partial scenes (regimes, chain patterns) combined with a preset.
PARTS = "parts"
#: Presets and parts one scene may combine.
MAX_PRESETS = 16


@dataclass(frozen=True)
class Scene:
    """A validated scene.

    Attributes
    ----------
    data : Node
        Every key of the schema, defaults filled, read-only.
    kind : str
        "cvt", "rotor" or "torsional" (which machine the scene describes).
    source : str
        Where it came from (file path, ``preset:NAME`` or ``<dict>``).
    """

    data: Node
    kind: str
    source: str

    def __getattr__(self, name: str) -> Any:
        try:
            return self.data[name]
        except KeyError:
            raise AttributeError(name) from None

    def to_toml(self) -> str:
        """The full resolved scene (defaults included) as TOML text."""
        return tomli_w.dumps(_drop_none(thaw(self.data)))

    def replace(self, overrides: Mapping[str, Any]) -> Scene:
        """A new scene with ``overrides`` (nested dict) merged in and re-validated."""
        return scene_from_dict(merge(_drop_none(thaw(self.data)), overrides), source=self.source)


#: Largest scene file read, bytes (the reference scenes are ~2 KiB).
MAX_SCENE_BYTES = 1 << 20


def _drop_none(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _drop_none(v) for k, v in value.items() if v is not None}
    if isinstance(value, list):
        return [_drop_none(v) for v in value]
    return value


def merge(base: Mapping[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    """Deep-merge ``override`` into ``base``: tables merge, everything else replaces (the ``solver`` table's
    options go with its method: :func:`_solver_below`)."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(_solver_below(out[key], value) if key == "solver" else out[key], value)
        else:
            out[key] = value
    return out


def _solver_below(below: Mapping[str, Any], over: Mapping[str, Any]) -> Mapping[str, Any]:
    """The ``solver`` table ``below`` as the layer ``over`` builds on: without its ``options`` where ``over`` names
    another method and no options (a preset's method options, e.g. strang-friction's scheme, are refused by another
    method)."""
    if "method" in over and over["method"] != below.get("method") and "options" not in over:
        return {k: v for k, v in below.items() if k != "options"}
    return below


def preset_names() -> list[str]:
    """Names of the built-in presets (complete scenes), sorted."""
    return _names(resources.files(PRESET_PACKAGE))


def part_names() -> list[str]:
    """Names of the built-in parts: partial scenes (a regime, a chain pattern) to combine with a preset,
    ``preset = ["chain-S2", "regime-A"]``."""
    return _names(resources.files(PRESET_PACKAGE).joinpath(PARTS))


def _names(folder) -> list[str]:
    return sorted(f.name[:-5] for f in folder.iterdir() if f.name.endswith(".toml"))


def preset_text(name: str) -> str:
    """TOML text of a built-in preset or part (with its provenance comments)."""
    folder = resources.files(PRESET_PACKAGE)
    if name in part_names():
        folder = folder.joinpath(PARTS)
    elif name not in preset_names():
        from cvtfem.scene.schema.base import _suggest

        known = preset_names() + part_names()
        raise InputError("preset", name, "must name a built-in preset or part (see `cvtfem scenes`)",
                         _suggest(name, known) or "available: " + ", ".join(known))
    return folder.joinpath(f"{name}.toml").read_text(encoding="utf-8")


def _parse(text: str, source: str) -> dict[str, Any]:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(source, "<file>", f"must be valid TOML: {err}") from None
    except RecursionError:
        raise InputError(source, "<file>", "must be valid TOML nested to a sane depth (arrays or tables "
                         "nested too deeply to parse)") from None


def _read_scene_file(path: Path) -> str:
    """The text of a scene file: readable, at most :data:`MAX_SCENE_BYTES`, UTF-8."""
    try:
        size = path.stat().st_size
        if size > MAX_SCENE_BYTES:
            raise InputError("SCENE", str(path), f"must be a scene file of at most {MAX_SCENE_BYTES // 1024} KiB "
                             f"({size} bytes given): scenes are short TOML files")
        data = path.read_bytes()
    except OSError as err:
        raise InputError("SCENE", str(path), f"must be a readable file ({err.strerror})") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[:err.start].count(b"\n") + 1
        raise InputError("SCENE", str(path), f"must be UTF-8 text (TOML): byte {data[err.start]:#04x} at line {line} "
                         "is not") from None


def resolve_presets(data: Mapping[str, Any], seen: tuple[str, ...] = ()) -> dict[str, Any]:
    """Expand ``preset = "NAME"`` or ``preset = ["NAME", "PART", ...]`` (recursively) into a plain merged
    document: the presets and parts merged in order, then the scene's own keys; the resolved document keeps
    the names as one comma-separated string."""
    if data.get("preset") in (None, ""):
        return dict(data)
    merged: dict[str, Any] = {}
    names = _preset_list(data["preset"])
    for name in names:
        if name in seen:
            raise InputError("preset", name, "must not form a cycle", " -> ".join(seen + (name,)))
        merged = merge(merged, resolve_presets(_parse(preset_text(name), f"preset {name}"), seen + (name,)))
    merged = merge(merged, {k: v for k, v in data.items() if k != "preset"})
    merged["preset"] = ", ".join(names)
    return merged


def _preset_list(value: Any) -> list[str]:
    """The preset names of a ``preset`` value: a name, a list of names, or names separated by commas."""
    if isinstance(value, str):
        names = value.split(",")
    elif isinstance(value, list) and value and all(isinstance(v, str) for v in value):
        names = value
    else:
        raise InputError("preset", value, "must be a preset name or a list of preset and part names "
                         "(merged in order; see `cvtfem scenes`)")
    names = [n.strip() for n in names]
    if not all(names):
        raise InputError("preset", value, "must not hold an empty name")
    if len(names) > MAX_PRESETS:
        raise InputError("preset", f"{len(names)} names", f"must hold at most {MAX_PRESETS} presets and parts")
    return names


def scene_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scene:
    """Validate a parsed scene document (presets expanded here)."""
    resolved = resolve_presets(data)
    validated = validate(SCENE, resolved)
    _refuse_unread(validated, data)
    return Scene(data=Node(validated), kind=scene_kind(validated), source=source)


def _refuse_unread(validated: Mapping[str, Any], data: Mapping[str, Any]) -> None:
    """A key the scene's CVT model does not read (:func:`~cvtfem.scene.schema.cvt.unread_keys`) that the scene sets
    to another value than its presets give or the schema's default is an :class:`InputError`, not a value silently
    ignored; a scene without presets (it must write every key) and a stored resolved scene (the presets' values, or
    the schema's default where an older preset held it: ``face_inclination`` 0 before session 13) pass."""
    from cvtfem.scene.schema.cvt import unread_keys

    if validated.get("cvt") is None or data.get("preset") in (None, ""):
        return
    model = validated["cvt"]["model"]
    unread = unread_keys(validated["cvt"])
    if not unread:
        return
    presets = resolve_presets({"preset": data["preset"]})
    for key, what in unread.items():
        written, given, default = _lookup(data, key), _lookup(presets, key), _schema_default(key)
        allowed = [v for v in (given, default) if v is not None]
        if written is not None and allowed and written not in allowed:
            also = f" or the default {default!r}" if given is not None and default not in (None, given) else ""
            raise InputError(key, written, f"is not read by `{model}`: it is {what}; leave it at its presets' value "
                             f"{allowed[0]!r}{also} (a changed value would be ignored)")


def _schema_default(key: str) -> Any:
    """The schema's default of the dotted key (None where it has none or the path is not a plain key)."""
    node = SCENE
    for part in key.split("."):
        node = node.child(part) if isinstance(node, Table) else None
    return None if not isinstance(node, Key) or node.required else node.default


def _lookup(doc: Mapping[str, Any], key: str) -> Any:
    """The value at a dotted key of a nested document, None where a part is missing."""
    for part in key.split("."):
        if not isinstance(doc, Mapping) or part not in doc:
            return None
        doc = doc[part]
    return doc


def load_scene(spec: str | Path, overrides: Mapping[str, Any] | None = None) -> Scene:
    """Load a scene from a TOML file or a preset name.

    Parameters
    ----------
    spec : str or Path
        A path to a ``.toml`` file, the name of a built-in preset, or a preset and parts separated by
        commas (``"band-6+2n,regime-A"``).
    overrides : mapping, optional
        Nested keys merged over the file's content before validation.
    """
    path = Path(spec)
    try:
        exists = path.exists()
    except OSError as err:   # e.g. a name too long for the file system
        raise InputError("SCENE", str(spec), f"must be an existing TOML file or a preset name ({err.strerror})",
                         "see `cvtfem scenes` for presets") from None
    if path.suffix == ".toml" or exists:
        if not path.is_file():
            raise InputError("SCENE", str(spec), "must be an existing TOML file or a preset name",
                             "see `cvtfem scenes` for presets")
        data, source = _parse(_read_scene_file(path), str(path)), str(path)
    else:
        names = _preset_list(str(spec))
        for name in names:
            preset_text(name)  # raises a clear error for an unknown name
        if not set(names) & set(preset_names()):
            raise InputError("SCENE", str(spec), "must name a preset (a complete scene), alone or with parts: "
                             f"{', '.join(names)} {'is a part' if len(names) == 1 else 'are parts'}",
                             f"e.g. chain-S2,{names[0]}")
        data, source = {"preset": str(spec)}, f"preset:{spec}"
    return scene_from_dict(merge(data, overrides or {}), source=source)
