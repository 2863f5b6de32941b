"""The whole report, as the README's first command writes it, opened in headless Chromium (Debian chromium and
chromium-driver, driven by python3-selenium): every image loaded, no console error, a screenshot kept in the build
folder (report_screenshot.png)."""
import os
import subprocess
import time
from pathlib import Path

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service

#: What a citation of a file outside the repository looks like (the report cites the papers and docs/ pages).
OUTSIDE = ("MATH.md", "shared/", "/work/", "seeds/")

CLI = os.environ["AFMKIT_CLI"]
BUILD = Path(os.environ["AFMKIT_BUILD_DIR"])


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    start = time.monotonic()
    r = subprocess.run([CLI, "report", "--output-dir", str(out)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    print(f"afmkit report took {time.monotonic() - start:.1f} s\n{r.stderr}")  # shown with pytest -s
    return out


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for arg in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--allow-file-access-from-files", "--window-size=1280,1000"]:
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    yield driver
    driver.quit()


def test_the_report_opens_with_every_image_loaded_and_no_console_error(report_dir, browser):
    from afmkit.report import figure_ids

    browser.get((report_dir / "index.html").as_uri())
    # wait for every image to finish (loaded or failed)
    deadline = time.monotonic() + 30
    while not browser.execute_script("return Array.from(document.images).every(i => i.complete)"):
        assert time.monotonic() < deadline, "images still loading after 30 s"
        time.sleep(0.2)
    images = browser.execute_script(
        "return Array.from(document.images).map(i => [i.getAttribute('src'), i.naturalWidth, i.naturalHeight])")
    assert len(images) == len(figure_ids())
    for src, width, height in images:
        assert width > 0 and height > 0, f"{src} did not load"
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert errors == []
    # every figure has its section, caption and an entry in the contents; the key-numbers table is filled
    for fid in figure_ids():
        assert browser.execute_script(f"return document.getElementById('{fid}') !== null"), fid
    assert browser.execute_script("return document.querySelectorAll('figcaption').length") == len(figure_ids())
    rows = browser.execute_script("return document.querySelectorAll('#numbers + table tr').length")
    assert rows > 10
    # the page cites the papers and this repository's docs only, never a file outside the repository
    text = browser.execute_script("return document.body.innerText")
    for outside in OUTSIDE:
        assert outside not in text, f"the page cites '{outside}' (a file outside the repository)"
    # a screenshot of the whole page, kept for people to look at
    height = browser.execute_script("return document.documentElement.scrollHeight")
    browser.set_window_size(1280, min(height, 16000))
    assert browser.save_screenshot(str(BUILD / "report_screenshot.png"))
    assert (BUILD / "report_screenshot.png").stat().st_size > 10000


def test_the_report_folder_holds_the_page_and_its_figures_only(report_dir):
    names = sorted(p.name for p in report_dir.iterdir())
    assert names == ["figures", "index.html"]
    pngs = sorted(p.stem for p in (report_dir / "figures").iterdir())
    from afmkit.report import figure_ids

    assert pngs == sorted(figure_ids())
