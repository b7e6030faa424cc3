"""A mesh folder walk: any file name is taken (non-UTF-8 bytes shown escaped), a tagged cache folder never is."""

from __future__ import annotations

import os

import pandas as pd

from graspaug.io.sources import CACHE_TAG, folder_sources, tag_cache
from graspaug.io.tables import read_table, write_table


def test_a_non_utf8_file_name_is_a_source_whose_name_any_table_holds(tmp_path):
    (tmp_path / "box.stl").write_text("solid")
    with open(os.path.join(os.fsencode(tmp_path), b"caf\xe9.stl"), "w") as f:
        f.write("solid")
    sources = folder_sources(tmp_path)
    assert [s.name for s in sources] == ["folder:box.stl", "folder:caf\\xe9.stl"]
    assert [s.shape_id for s in sources] == ["f_box", "f_caf_xe9"] and all(s.path.exists() for s in sources)
    table = pd.DataFrame({"source": [s.name for s in sources]})
    write_table(table, tmp_path / "t.parquet")  # raised UnicodeEncodeError with the raw name
    assert read_table(tmp_path / "t.parquet")["source"].tolist() == table["source"].tolist()


def test_a_tagged_cache_inside_the_corpus_is_never_walked(tmp_path):
    (tmp_path / "box.stl").write_text("solid")
    cache = tmp_path / ".graspaug-cache/evaluate"
    (cache / "0123/shapes").mkdir(parents=True)
    (cache / "0123/shapes/f_box.ply").write_text("ply")
    assert len(folder_sources(tmp_path)) == 2  # untagged: read as an object
    tag_cache(cache)
    assert (cache / CACHE_TAG).read_text().startswith("Signature: 8a477f597d28d172789f06886806bc55")
    assert [s.name for s in folder_sources(tmp_path)] == ["folder:box.stl"]
