#!/usr/bin/env python3
"""Screenshots of the converge report for the README: docs/images/report.png (the page) and
docs/images/heatmap.png (the FLIP heatmap of the Path 16-spp rung), from a fresh
`rtis converge` of the course's box at 180 px, in headless Chromium.

Needs the venv of cluster/setup.sh with selenium, and Debian's chromium and chromium-driver:
    .venv/bin/pip install selenium && .venv/bin/python bench/report_screenshot.py
"""

import base64
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RTIS = os.path.join(ROOT, "target", "release", "rtis")
IMAGES = os.path.join(ROOT, "docs", "images")


def main():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By

    with tempfile.TemporaryDirectory() as d:
        subprocess.run([RTIS, "converge", "--runs", "1", "--out", d], check=True)
        opts = webdriver.ChromeOptions()
        opts.binary_location = "/usr/bin/chromium"
        for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1250,1500"]:
            opts.add_argument(a)
        b = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
        try:
            b.get("file://" + os.path.join(d, "report.html"))
            rows = b.find_elements(By.CSS_SELECTOR, "#rows tr")
            pick = next(k for k, r in enumerate(rows) if "spp=16" in r.text)
            rows[pick].click()
            b.execute_script("const s = document.getElementById('slider'); s.value = 35;"
                             "s.dispatchEvent(new Event('input'));")
            b.execute_script("window.scrollTo(0, 0)")
            b.save_screenshot(os.path.join(IMAGES, "report.png"))
            src = b.find_element(By.ID, "flipmap").get_attribute("src")
            with open(os.path.join(IMAGES, "heatmap.png"), "wb") as f:
                f.write(base64.b64decode(src.split(",", 1)[1]))
        finally:
            b.quit()


if __name__ == "__main__":
    main()
