"""The docs site builds with ``mkdocs build --strict`` (mkdocs.yml): a broken link, a missing page, a page left out of
the nav or an API docstring that does not parse fails it. Its pages point nowhere outside the repository.

Needs the docs' packages (docs/requirements.txt; .ci/requirements.txt installs them); skipped with the reason
otherwise, failed instead where STICKSLIP_REQUIRE_DOCS is set (as .ci/run does).
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _nav_pages(entries):
    for entry in entries:
        for value in entry.values() if isinstance(entry, dict) else [entry]:
            yield from _nav_pages(value) if isinstance(value, list) else [value]


def test_mkdocs_build_strict(tmp_path):
    try:
        import mkdocs  # noqa: F401
    except ImportError:
        reason = "mkdocs is not installed (pip install -r docs/requirements.txt)"
        if os.environ.get("STICKSLIP_REQUIRE_DOCS"):
            pytest.fail(reason)
        pytest.skip(reason)
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                           cwd=ROOT, capture_output=True, text=True, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-5000:]
    parameters = (tmp_path / "site" / "parameters" / "index.html").read_text()
    assert "driven_slab" in parameters and "G/h^2" in parameters  # the generated tables
    reference = (tmp_path / "site" / "reference" / "index.html").read_text()
    assert "StudyResults" in reference and "wide" in reference  # the API reference from the docstrings


def test_every_page_is_in_the_nav_and_no_user_page_points_outside_the_repository():
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text().replace("!!python", "#"))
    pages = set(_nav_pages(config["nav"]))
    assert pages == {path.name for path in (ROOT / "docs").glob("*.md")}
    development = set(_nav_pages([entry for entry in config["nav"] if "Development record" in entry]))
    for name in pages - development:
        text = (ROOT / "docs" / name).read_text()
        assert not re.search(r"\.\./shared|`shared/", text), f"docs/{name} sends the reader outside the repository"
    assert not re.search(r"\.\./shared/[a-z-]+\.md", (ROOT / "README.md").read_text())
