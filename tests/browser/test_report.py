"""The converge report as a user sees it, in headless Chromium (Debian's chromium and
chromium-driver, driven by selenium): it loads without console errors, its images and plot are
present and visible, and the slider moves the split between rung and reference.

Run by .ci/run after `bash cluster/setup.sh` (the venv) and `pip install selenium`:
    .venv/bin/python -m pytest tests/browser
"""

import os
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RTIS = os.path.join(ROOT, "target", "release", "rtis")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("converge")
    subprocess.run([RTIS, "converge", "--width", "48", "--runs", "1", "--seeds", "2",
                    "--reference-spp", "16", "--out", str(out)], check=True, capture_output=True)
    return out / "report.html"


@pytest.fixture(scope="module")
def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1400,1200"]:
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    yield d
    d.quit()


def test_report_loads_shows_its_parts_and_the_slider_works(report, browser):
    from selenium.webdriver.common.by import By

    browser.get(report.as_uri())
    # No console errors (and nothing fetched from a network: every image is a data: URI).
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors
    assert "error vs time" in browser.title, browser.title
    # Images: the reference, the rung, both heatmaps and the colour bars, decoded and visible.
    imgs = browser.find_elements(By.TAG_NAME, "img")
    assert len(imgs) >= 6
    for img in imgs:
        assert img.get_attribute("src").startswith("data:image/png;base64,")
        assert browser.execute_script("return arguments[0].complete && arguments[0].naturalWidth > 0", img)
        assert img.is_displayed()
    # The plot: one point per rung, visible; the table has as many rows.
    points = browser.find_elements(By.CSS_SELECTOR, "#plot circle.pt")
    rows = browser.find_elements(By.CSS_SELECTOR, "#rows tr")
    assert len(points) == len(rows) >= 10
    assert browser.find_element(By.ID, "plot").is_displayed()
    # The slider moves the split between the rung (left) and the reference (right).
    top = browser.find_element(By.ID, "top")
    before = top.value_of_css_property("clip-path")
    slider = browser.find_element(By.ID, "slider")
    browser.execute_script(
        "arguments[0].value = 80; arguments[0].dispatchEvent(new Event('input'));", slider)
    after = top.value_of_css_property("clip-path")
    assert before != after and "20%" in after, (before, after)
    # Clicking a point shows that rung and marks its row.
    points[-1].click()
    assert "sel" in rows[-1].get_attribute("class")
    name = browser.find_element(By.ID, "rungname").text
    assert name.startswith("Path"), name
    # The equal-error view answers for every family.
    assert len(browser.find_elements(By.CSS_SELECTOR, "#equal tr")) >= 3
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]


def test_report_shows_where_the_time_goes_and_the_fireflies(report, browser):
    from selenium.webdriver.common.by import By

    browser.get(report.as_uri())
    rows = browser.find_elements(By.CSS_SELECTOR, "#rows tr")
    maps = ["timemap", "errmap", "productmap", "ffimage"]

    def shown():
        out = {}
        for m in maps:
            img = browser.find_element(By.ID, m)
            assert img.get_attribute("src").startswith("data:image/png;base64,")
            assert browser.execute_script(
                "return arguments[0].complete && arguments[0].naturalWidth > 0", img)
            assert img.is_displayed()
            out[m] = img.get_attribute("src")
        return out

    # The time, error and variance x time maps of the first rung (2 seeds: its variance is
    # known), its scale written out.
    first = shown()
    assert float(browser.find_element(By.ID, "timemax").text) > 0
    # Its fireflies: one circle per table row, at most eight, on the rung's image, each row
    # naming a path of surfaces.
    circles = browser.find_elements(By.CSS_SELECTOR, "#ffmarks circle.ff")
    table = browser.find_elements(By.CSS_SELECTOR, "#fftable tr")
    assert 1 <= len(circles) == len(table) <= 8
    assert all(c.is_displayed() for c in circles)
    # Choosing the last rung (Path at the most spp) changes every map and the fireflies.
    rows[-1].click()
    last = shown()
    assert all(first[m] != last[m] for m in maps)
    table = browser.find_elements(By.CSS_SELECTOR, "#fftable tr")
    assert len(table) >= 1
    path = table[0].find_elements(By.TAG_NAME, "td")[-1].text
    assert "Phong" in path or "Mirror" in path or "Transmissive" in path, path
    # Ranked: each firefly stands out no more than the one before.
    excess = [float(r.find_elements(By.TAG_NAME, "td")[4].text) for r in table]
    assert excess == sorted(excess, reverse=True), excess
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]


def test_report_says_when_a_rung_has_no_variance_to_measure(tmp_path, browser):
    from selenium.webdriver.common.by import By

    # One seed: the 1-spp rungs have no spread to measure; Path at 4 spp and more has.
    subprocess.run([RTIS, "converge", "--width", "32", "--runs", "1", "--seeds", "1",
                    "--reference-spp", "16", "--out", str(tmp_path)], check=True,
                   capture_output=True)
    browser.get((tmp_path / "report.html").as_uri())
    rows = browser.find_elements(By.CSS_SELECTOR, "#rows tr")
    note = browser.find_element(By.ID, "productnote")
    product = browser.find_element(By.ID, "productmap")
    assert note.is_displayed() and not product.is_displayed()
    rows[-1].click()
    assert product.is_displayed() and not note.is_displayed()
    assert not [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
