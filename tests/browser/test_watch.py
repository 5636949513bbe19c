"""`rtis watch` as a user sees it, in headless Chromium (selenium): the page shows the render
as it refines; saving the scene changes the image; breaking it shows the located error while
the old image stays; fixing it clears the error; the exposure slider, the display switch and
the pixel inspector work; no console errors.

Run by .ci/run after `bash cluster/setup.sh` (the venv) and `pip install selenium`:
    .venv/bin/python -m pytest tests/browser
"""

import os
import subprocess
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RTIS = os.path.join(ROOT, "target", "release", "rtis")
CORNELL = os.path.join(ROOT, "scenes", "cornell.ron")


def scene_text(depth):
    return (f'Scene(extends: "{CORNELL}", film: (width: 48, height: 36, spp: 32),\n'
            f'      shader: Path(max_depth: {depth}))\n')


def save(path, text):
    # Written whole and renamed, as editors save.
    tmp = str(path) + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


@pytest.fixture()
def watch(tmp_path):
    scene = tmp_path / "scene.ron"
    save(scene, scene_text(3))
    proc = subprocess.Popen([RTIS, "watch", "--port", "0", str(scene)],
                            stderr=subprocess.PIPE, text=True)
    line = proc.stderr.readline()
    assert "http://127.0.0.1:" in line, line
    url = line.split("open ")[1].split(" ")[0]
    yield scene, url
    proc.kill()
    proc.wait()


@pytest.fixture(scope="module")
def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1400,1000", "--disable-background-networking"]:
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    yield d
    d.quit()


def wait(what, ok, timeout=60):
    start = time.time()
    while True:
        v = ok()
        if v:
            return v
        assert time.time() - start < timeout, what
        time.sleep(0.05)


def pixels(browser):
    """The canvas as shown (8-bit, after exposure and display curve)."""
    return browser.execute_script("return document.getElementById('img').toDataURL();")


def test_watch_page_follows_edits_and_errors(watch, browser):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.action_chains import ActionChains

    scene, url = watch
    browser.get(url)
    shown = lambda: browser.execute_script("return window.rtisShown.spp;")
    # The render refines to the scene's 32 spp; the side panel shows its figures.
    wait("the full render", lambda: shown() == 32)
    status = browser.find_element(By.ID, "status")
    wait("done", lambda: status.text.startswith("done: 32 of 32 spp"))
    assert "rays" in browser.find_element(By.ID, "estimate").text
    assert "shadows" in browser.find_element(By.ID, "effects").text
    assert len(browser.find_elements(By.CSS_SELECTOR, "#rays tr")) >= 5
    first = pixels(browser)

    # Exposure and display change what is shown, not the image held.
    slider = browser.find_element(By.ID, "exposure")
    browser.execute_script(
        "arguments[0].value = 2; arguments[0].dispatchEvent(new Event('input'));", slider)
    brighter = pixels(browser)
    assert brighter != first
    browser.execute_script(
        "arguments[0].value = 0; arguments[0].dispatchEvent(new Event('input'));", slider)
    assert pixels(browser) == first
    browser.execute_script(
        "const s = document.getElementById('display'); s.value = 'linear';"
        "s.dispatchEvent(new Event('change'));")
    assert pixels(browser) != first
    browser.execute_script(
        "const s = document.getElementById('display'); s.value = 'srgb';"
        "s.dispatchEvent(new Event('change'));")

    # The pixel inspector: radiance and samples under the cursor.
    canvas = browser.find_element(By.ID, "img")
    ActionChains(browser).move_to_element(canvas).perform()
    probe = browser.find_element(By.ID, "probe").text
    assert "32 spp" in probe and "R " in probe and "G " in probe, probe

    # Saving the scene changes the image.
    version = browser.execute_script("return window.rtisShown.version;")
    save(scene, scene_text(1))
    wait("the new image", lambda: browser.execute_script(
        "return window.rtisShown.version;") > version and shown() == 32)
    wait("the new image drawn", lambda: pixels(browser) != first)
    edited = pixels(browser)

    # Breaking it shows the located error; the old image stays.
    save(scene, "Scene(film: (width: 48, height: -1))\n")
    error = browser.find_element(By.ID, "error")
    wait("the error shown", lambda: error.is_displayed())
    assert "scene.ron:1:" in error.text and "height" in error.text, error.text
    time.sleep(0.5)
    assert pixels(browser) == edited

    # Fixing it clears the error.
    save(scene, scene_text(3))
    wait("the error cleared", lambda: not error.is_displayed())
    wait("the first image again", lambda: pixels(browser) == first)

    severe = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe, severe
