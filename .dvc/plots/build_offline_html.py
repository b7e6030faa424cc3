"""Write offline.html: DVC's plots page with Vega, Vega-Lite and Vega-Embed inline, so `dvc plots show`
draws with no network (a cluster node, a laptop on a train).

Usage, from this folder, with the npm registry reachable::

    npm pack vega@5.33.1 vega-lite@5.23.0 vega-embed@6.29.0
    python build_offline_html.py vega-5.33.1.tgz vega-lite-5.23.0.tgz vega-embed-6.29.0.tgz

The page has DVC's placeholders for the plots and the refresh tag but none for DVC's scripts (its CDN
<script> tags): `.dvc/config` names it as `plots.html_template`.
"""

import sys
import tarfile
from pathlib import Path

HERE = Path(__file__).parent
BUILDS = {"vega": "package/build/vega.min.js", "vega-lite": "package/build/vega-lite.min.js"}
BUILDS["vega-embed"] = "package/build/vega-embed.min.js"

HEAD = """<!DOCTYPE html>
<html>
<head>
    <meta charset="utf-8">
    {{refresh_tag}}
    <title>DVC plots</title>
    <!-- {versions} inline (BSD-3-Clause: .dvc/plots/LICENSE.*), so this
         page loads nothing from the network. Built by .dvc/plots/build_offline_html.py. -->
"""
TAIL = """    <style>
        body {
            font-family: sans-serif;
        }
        table {
            border-spacing: 15px;
        }
    </style>
</head>
<body>
    {plot_divs}
</body>
</html>
"""
PLACEHOLDERS = ("{scripts}", "{plot_divs}", "{refresh_tag}")


def read_build(tgz: Path, member: str) -> str:
    with tarfile.open(tgz) as tar:
        text = tar.extractfile(member).read().decode("utf-8")
    text = "\n".join(line for line in text.splitlines() if not line.startswith("//# sourceMappingURL="))
    # DVC fills the page with str.replace; a placeholder or a closing tag inside a library would break it
    assert not any(p in text for p in PLACEHOLDERS) and "</script" not in text.lower(), (tgz, member)
    return text


def main(tarballs: list[str]) -> None:
    by_name = {Path(t).name.rsplit("-", 1)[0]: Path(t) for t in tarballs}
    assert set(by_name) == set(BUILDS), f"expected npm tarballs of {sorted(BUILDS)}, got {sorted(by_name)}"
    versions = ", ".join(f"{n} {by_name[n].name.rsplit('-', 1)[1].removesuffix('.tgz')}" for n in BUILDS)
    scripts = "".join(
        f'    <script type="text/javascript">\n{read_build(by_name[n], m)}\n    </script>\n' for n, m in BUILDS.items()
    )
    page = HEAD.format(versions=versions) + scripts + TAIL
    (HERE / "offline.html").write_text(page, encoding="utf-8")


if __name__ == "__main__":
    main(sys.argv[1:])
