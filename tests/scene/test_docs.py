"""docs/scenes.md is generated from the schema and must be current."""
from __future__ import annotations

from cvtfem.scene.docs import scene_reference
from cvtfem.scene.schema import SCENE
from cvtfem.scene.schema.base import Key, Table, TableArray
from tests.conftest import ROOT


def _keys(table: Table):
    for item in table.items:
        if isinstance(item, Key):
            yield item
        elif isinstance(item, Table):
            yield from _keys(item)
        elif isinstance(item, TableArray):
            yield from _keys(item.item)


def test_committed_reference_is_current():
    committed = (ROOT / "docs" / "scenes.md").read_text(encoding="utf-8")
    assert committed == scene_reference(), "docs/scenes.md is stale: run `cvtfem docs scenes`"


def test_every_key_is_documented_with_unit():
    for key in _keys(SCENE):
        assert key.doc and key.doc[0].isupper() and key.doc.endswith("."), key.name
        if key.type in ("float", "float[]"):
            assert key.unit, f"{key.name} has no unit"
        assert f"| `{key.name}` |" in scene_reference()
