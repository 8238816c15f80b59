"""`stickslip browse` on the ci study in a real browser: Debian's Chromium driven by Playwright.

The command serves the study on 127.0.0.1 (a port the system picks); the browser opens the index, filters and sorts
the runs, follows a figure to its page and on to a run it was drawn from (two clicks: a figure's runs within three),
checks that every link and image of every page resolves, that no page is blank and that the console shows no
error, and saves a screenshot of each page it looks at into the test's temporary folder (look at them: they are
what a user sees). Nothing served can write: other methods than GET and HEAD are refused.

Needs Debian's ``chromium`` (tests/browser/packages.txt; `bash .ci/run` installs it) and the ``playwright`` package;
skipped with the reason otherwise, failed instead where STICKSLIP_REQUIRE_BROWSER is set (as .ci/run does).
"""

import os
import re
import shutil
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path
from urllib.parse import urljoin, urlsplit

import pytest

import stickslip
from stickslip.provenance.query import RUN_COLUMNS

pytestmark = pytest.mark.slow

CHROMIUM = Path("/usr/bin/chromium")


def _require(condition, reason):
    if not condition:
        if os.environ.get("STICKSLIP_REQUIRE_BROWSER"):  # set by .ci/run where it installed the browser
            pytest.fail(reason)
        pytest.skip(reason)


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium, headless, driven by Playwright (its own browser builds are not used)."""
    _require(CHROMIUM.is_file(), f"{CHROMIUM} is missing (apt-get install chromium; .ci/run installs it)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _require(False, "the playwright package is not installed (pip install -r .ci/requirements.txt)")
    with sync_playwright() as driver:
        launched = driver.chromium.launch(executable_path=str(CHROMIUM), args=["--no-sandbox"])
        yield launched
        launched.close()


@pytest.fixture(scope="module")
def served(ci_study, tmp_path_factory):
    """`stickslip browse --study ci` serving a copy of the ci study; yields its URL."""
    folder = tmp_path_factory.mktemp("browse") / "repository"
    shutil.copytree(ci_study, folder, symlinks=True, ignore=shutil.ignore_patterns(".snakemake"))
    process = subprocess.Popen([sys.executable, "-m", "stickslip", "browse", "--study", "ci", "--workdir", str(folder)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    match = re.match(r"^(http://127\.0\.0\.1:\d+/) ", line)
    if match is None:
        process.kill()
        pytest.fail(f"no URL from stickslip browse: {line!r} {process.stderr.read()}")
    yield match.group(1), stickslip.study("ci", workdir=folder)
    process.terminate()
    assert process.wait(timeout=30) in (0, 143), process.stderr.read()


#: The images of a page that could not be drawn, every one loaded first (a lazy one below the fold too).
DRAWN = """async () => {
    const images = Array.from(document.images);
    images.forEach(image => { image.loading = "eager"; });
    await Promise.all(images.map(image => image.decode().catch(() => null)));
    return images.filter(image => !(image.complete && image.naturalWidth > 0)).map(image => image.src);
}"""


class Visit:
    """A browser page that records console errors and failed requests."""

    def __init__(self, browser):
        self.page = browser.new_page(viewport={"width": 1400, "height": 1000})
        self.errors = []
        self.page.on("console", lambda message: message.type == "error" and self.errors.append(message.text))
        self.page.on("pageerror", lambda error: self.errors.append(str(error)))
        self.page.on("requestfailed", lambda request: self.errors.append(f"failed: {request.url}"))
        self.page.on("response", lambda response: response.status >= 400 and self.errors.append(
            f"{response.status}: {response.url}"))

    def open(self, url):
        self.page.goto(url, wait_until="load")
        self.check()

    def check(self):
        """Not blank: a heading and text; every image drawn (once the page after a click has loaded)."""
        self.page.wait_for_load_state("load")
        assert self.page.locator("h1").count() == 1 and len(self.page.inner_text("main")) > 100, self.page.url
        broken = self.page.evaluate(DRAWN)
        assert not broken, f"{self.page.url}: images not drawn: {broken}"
        assert not self.errors, f"{self.page.url}: {self.errors}"

    def shot(self, folder, name):
        path = folder / f"{name}.png"
        self.page.screenshot(path=str(path), full_page=True)
        assert path.stat().st_size > 10_000  # a page with content, not a blank one
        return path


def _status(url, method="GET"):
    try:
        with urllib.request.urlopen(urllib.request.Request(url, method=method), timeout=30) as response:
            return response.status
    except urllib.error.HTTPError as error:
        return error.code


def test_index_filters_and_sorts_the_runs(browser, served, tmp_path):
    url, study = served
    visit = Visit(browser)
    visit.open(url)
    runs = study.runs()
    assert visit.page.locator("#runs-table tbody tr").count() == len(runs)
    headings = visit.page.locator("#runs-table thead tr").first.inner_text()
    assert "k_drive [G/h^2]" in headings and "wall_time_s [s]" in headings and "n [1]" in headings  # vocabulary, units
    visit.shot(tmp_path, "index")
    visit.page.fill('input[data-column="kind"]', "solver")
    visible = visit.page.locator("#runs-table tbody tr:not([hidden])")
    assert visible.count() == len(study.runs(kind="solver")) > 0
    visit.page.fill('input[data-column="n"]', ">1")
    assert visible.count() == len(study.runs(kind="solver", n=[n for n in range(2, 10)])) > 0
    assert re.search(rf"{visible.count()} of {len(runs)} shown", visit.page.inner_text("#runs-count"))
    visit.page.click('#runs-table thead th[data-column="n"]')
    visit.page.click('#runs-table thead th[data-column="n"]')  # descending
    column = RUN_COLUMNS.index("n") + 1
    shown = [int(text) for text in visible.locator(f"td:nth-child({column})").all_inner_texts()]
    assert shown == sorted(shown, reverse=True) and min(shown) > 1
    visit.shot(tmp_path, "index-filtered")
    visit.check()


def test_a_figures_runs_in_two_clicks(browser, served, tmp_path):
    url, study = served
    figure = study.figures().iloc[0]
    visit = Visit(browser)
    visit.open(url)
    visit.page.click(f'a[href="figures/{figure["figure"]}.html"]')  # click 1: the figure
    visit.check()
    page = visit.page.inner_text("main")
    assert figure["code_hash"] in page and figure["git_commit"] in page and "--forcerun figure_" in page
    assert "study.events(run_id=[" in page
    visit.shot(tmp_path, "figure")
    drawn = visit.page.locator("ul.drawn a[href^='../runs/']")
    assert drawn.count() > 0
    run_id = drawn.first.inner_text()
    drawn.first.click()  # click 2: a run it was drawn from
    visit.check()
    assert visit.page.url.endswith(f"/runs/{run_id}.html")
    page = visit.page.inner_text("main")
    for section in ("Increments", "Slip events", "Parameters", "Provenance", "Arithmetic"):
        assert section in page
    assert len(study.events(run_id=run_id)) == visit.page.locator("#events-table tbody tr").count() > 0
    visit.shot(tmp_path, "run")


def test_every_link_resolves_and_nothing_can_write(browser, served):
    url, _ = served
    visit = Visit(browser)
    pages, seen = [url], set()
    while pages:
        page = pages.pop()
        if page in seen:
            continue
        seen.add(page)
        visit.open(page)
        targets = visit.page.evaluate("[...document.querySelectorAll('a[href], img[src], link[href], script[src]')]"
                                      ".map(e => e.href || e.src)")
        for target in targets:
            if target.startswith("data:"):
                continue
            assert urlsplit(target).netloc == urlsplit(url).netloc, f"{page} links outside the site: {target}"
            target = urljoin(target, urlsplit(target).path)  # without the #anchor
            assert _status(target) == 200, f"{page}: broken link {target}"
            if target.endswith(".html"):
                pages.append(target)
    assert len(seen) > 20  # the index, every figure's and every run's page
    assert _status(url + "index.html", "POST") == 501 and _status(url + "index.html", "PUT") == 501
    assert _status(url + "../../etc/passwd") == 404


def test_the_workflow_writes_the_pages_as_a_static_site(browser, ci_study, tmp_path):
    """`snakemake browse` writes results/ci/browse/: the same pages, read from files (file://) without a server."""
    folder = tmp_path / "repository"
    shutil.copytree(ci_study, folder, symlinks=True)  # with Snakemake's metadata: only the browse rule runs
    built = subprocess.run([sys.executable, "-m", "snakemake", "browse", "--cores", "1", "--configfile",
                            "workflow/config/ci.yaml"], cwd=folder, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    assert "rule browse:" in built.stdout + built.stderr and "rule database:" not in built.stdout + built.stderr
    index = folder / "results" / "ci" / "browse" / "index.html"
    visit = Visit(browser)
    visit.open(index.as_uri())
    assert visit.page.locator("#runs-table tbody tr").count() == len(stickslip.study("ci", workdir=folder).runs())
    visit.page.locator("ul.figures a").first.click()
    visit.check()
    visit.shot(tmp_path, "static-figure")
