"""The map explorer (index.html) in a real browser: headless Chromium driven by
Selenium opens the page from file://, hovers and clicks cells and types
targets, and checks what the page shows against cells.parquet, designs.parquet
and `cablemap feasible --json`. A screenshot is kept as a test artefact.

Usage: check_explorer.py MAP_DIR CABLEMAP_BINARY SCREENSHOT.png
Prints one line per check and "python: N passed, M failed"; exits 1 on any
failure.
"""

import json
import math
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import pandas as pd
from harness import finish, run_check
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import WebDriverWait

map_dir = Path(sys.argv[1]).resolve()
binary = sys.argv[2]
screenshot = Path(sys.argv[3])

cells = pd.read_parquet(map_dir / "cells.parquet")
designs = pd.read_parquet(map_dir / "designs.parquet")
# The planar map of a cable sweep sits in the cable map's folder, whose
# summary says how many cables the actuator has: its page shows every cable.
parent_summary = map_dir.parent / "summary.json"
cable_map = json.loads(parent_summary.read_text()) if parent_summary.exists() else {}
several = cable_map.get("kind") == "cables"
n_cables = cable_map.get("cables", 1)

options = webdriver.ChromeOptions()
options.binary_location = "/usr/bin/chromium"
profile = tempfile.mkdtemp(prefix="cablemap-chromium-")
for flag in [
    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-quic", f"--user-data-dir={profile}", "--window-size=1400,1100",
]:
    options.add_argument(flag)
driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def close(a, b, rel=2e-4):
    return abs(a - b) <= rel * abs(b) + 1e-9


def hover(map_name, ix, iy, click=False):
    canvas = driver.find_element(By.ID, "map-main" if map_name == "main" else f"map-{map_name}")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", canvas)
    pos = driver.execute_script("return window.cablemapCellCentre(arguments[0], arguments[1], arguments[2]);", map_name, int(ix), int(iy))
    chain = ActionChains(driver).move_to_element_with_offset(canvas, pos["offsetX"], pos["offsetY"])
    if click:
        chain = chain.click()
    chain.perform()


def check_loads():
    driver.get((map_dir / "index.html").as_uri())
    WebDriverWait(driver, 30).until(lambda d: d.execute_script("return window.cablemapReady === true;"))
    header = driver.find_element(By.ID, "header").text
    summary = json.loads((map_dir / "summary.json").read_text())
    assert "L = 65 mm" in header and "EI = 115.117" in header, header
    assert "per unit rest length" in header, header
    assert f"{summary['tension_range_n'][0]}" in header
    if several:
        assert f"{n_cables} cables, each with its own routing and tension" in header, header
        assert "cable 2:" in header, header
    # Equal aspect: the main map's drawn height over width equals the mm extents'.
    ratio = driver.execute_script(
        "const c = document.getElementById('map-main'); return [c.clientWidth, c.clientHeight];")
    assert ratio[0] > 200 and ratio[1] > 200, ratio


def sample_cells():
    busiest = cells.sort_values("count").iloc[-1]
    median = cells.sort_values("count").iloc[len(cells) // 2]
    edge = cells.sort_values(["ix", "iy"]).iloc[0]
    return [busiest, median, edge]


def check_hover():
    for map_name in ["main", "p90"]:
        for c in sample_cells():
            hover(map_name, c["ix"], c["iy"])
            info = driver.find_element(By.ID, "info-cell")
            assert (int(info.get_attribute("data-ix")), int(info.get_attribute("data-iy"))) == (c["ix"], c["iy"]), (
                info.get_attribute("data-ix"), info.get_attribute("data-iy"), c["ix"], c["iy"])
            assert int(driver.find_element(By.ID, "info-count").text) == c["count"]
            for k in range(3):
                row = driver.find_element(By.CSS_SELECTOR, f"#info tr[data-k='{k}']")
                for stat in ["min", "p10", "p90", "max"]:
                    shown = float(row.find_element(By.CLASS_NAME, f"v-{stat}").text)
                    assert close(shown, c[f"a{k}_{stat}"]), (k, stat, shown, c[f"a{k}_{stat}"])
            modes = driver.find_element(By.ID, "info-modes").text.split()
            assert [int(m.split(":")[1]) for m in modes] == [int(c[f"mode_{m}"]) for m in range(12)]


def check_click():
    for c in sample_cells():
        hover("main", c["ix"], c["iy"], click=True)
        want = designs[(designs["ix"] == c["ix"]) & (designs["iy"] == c["iy"])]
        assert int(driver.find_element(By.ID, "designs-count").text) == len(want) > 0
        rows = driver.find_elements(By.CSS_SELECTOR, "#designs tr.design-row")
        assert len(rows) == len(want)
        if not several:
            # Routings are shown as pasteable --routing arguments.
            first = rows[0].find_elements(By.TAG_NAME, "td")[1].text
            assert first.startswith("--routing ") and len(first.split()[1].split(",")) == 5, first
            continue
        # Every cable's routing and tension, and a command that solves the row again to its tip.
        cells_of_first = rows[0].find_elements(By.TAG_NAME, "td")
        assert len(cells_of_first) == 1 + 2 * n_cables + 1 + len([c for c in designs.columns if re.fullmatch(r"a\d+", c)])
        for k in range(n_cables):
            assert len(cells_of_first[1 + 2 * k].text.split(",")) == 5, cells_of_first[1 + 2 * k].text
        commands = driver.find_elements(By.CSS_SELECTOR, "#designs tr.design-command code.command")
        assert len(commands) == len(want)
        for command, (_, design) in list(zip(commands, want.iterrows()))[:2]:
            words = shlex.split(command.text)
            assert words[:2] == ["cablemap", "simulate"] and words.count("--cable") == n_cables, words
            out = subprocess.run([binary] + words[1:] + ["--json"], check=True, capture_output=True, text=True)
            tip = json.loads(out.stdout)
            gap = math.hypot(tip["tip_x_mm"] - design["tip_x_mm"], tip["tip_y_mm"] - design["tip_y_mm"])
            assert gap < 1e-3, (command.text, gap)


def feasible_cli(target):
    out = subprocess.run([binary, "feasible", "--map", str(map_dir), "--target", target, "--json"],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def check_targets():
    c = sample_cells()[0]
    summary = json.loads((map_dir / "summary.json").read_text())
    x = summary["x_min_mm"] + (c["ix"] + 0.5) * summary["cell_mm"]
    y = summary["y_min_mm"] + (c["iy"] + 0.5) * summary["cell_mm"]
    mid = lambda k: 0.5 * (c[f"a{k}_p10"] + c[f"a{k}_p90"])
    targets = [
        f"x={x},y={y}",
        f"x={x},y={y},a0={mid(0)},a1={mid(1)}",
        f"x={x},y={y},a0={c['a0_max'] + 1.0}",
        f"x={x},y={y},a0={c['a0_p90'] + 0.25 * (c['a0_max'] - c['a0_p90'])}",
        "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015",
        "x=10,y=50,a0=0.015,a1=-0.07,a2=-0.03",
        "x=80,y=0",
        f"x={x}",
        f"y={y},a0={mid(0)}",
    ]
    seen = set()
    for t in targets:
        box = driver.find_element(By.ID, "target")
        box.clear()
        box.send_keys(t, Keys.ENTER)
        shown = driver.execute_script("return window.cablemapLastVerdict;")
        want = feasible_cli(t)
        assert shown["verdict"] == want["verdict"], (t, shown, want["verdict"], want["reasons"])
        assert shown["tip"]["count"] == want["tip_cell"]["count"], (t, shown["tip"], want["tip_cell"])
        assert shown["tip"]["neighbourhood_count"] == want["tip_cell"]["neighbourhood_count"], t
        assert shown["mode"] == want["mode"]["mode"], (t, shown["mode"], want["mode"])
        shown_el = driver.find_element(By.ID, "verdict-text")
        assert shown_el.get_attribute("data-verdict") == want["verdict"], (shown_el.get_attribute("data-verdict"), want["verdict"])
        # The words of `cablemap feasible`'s text report, reasons included, and its next command.
        text_out = subprocess.run([binary, "feasible", "--map", str(map_dir), "--target", t],
                                  check=True, capture_output=True, text=True).stdout
        assert text_out.startswith(f"verdict   {shown_el.text}\n"), (shown_el.text, text_out)
        # Numbers are printed to other precisions on the page: compare the words.
        words = lambda text: re.sub(r"-?\d[\d.]*(e[+-]?\d+)?", "#", text)
        page = words(driver.find_element(By.ID, "verdict").text)
        for reason in want["reasons"]:
            assert words(reason) in page, (reason, page)
        next_cli = [l for l in text_out.splitlines() if l.startswith("next      ")][0].split()[1:]
        next_page = driver.find_element(By.ID, "verdict-next").text.split()
        assert next_page[:3] == next_cli[:3] == ["cablemap", "design", "--target"], (next_page, next_cli)
        assert next_page[4:] == next_cli[4:] == ["--map", str(map_dir)], (next_page, next_cli)
        components = lambda arg: {k: float(v) for k, v in (kv.split("=") for kv in arg.split(","))}
        assert components(next_page[3]) == components(next_cli[3]) == components(t), (next_page, next_cli, t)
        seen.add(want["verdict"])
    assert {"feasible", "unreachable"} <= seen, seen
    # Bad input gets a message, not a verdict.
    box = driver.find_element(By.ID, "target")
    box.clear()
    box.send_keys("x=abc", Keys.ENTER)
    assert "not a finite number" in driver.find_element(By.ID, "verdict").text


def check_controls():
    from selenium.webdriver.support.ui import Select
    Select(driver.find_element(By.ID, "coef")).select_by_value("1")
    Select(driver.find_element(By.ID, "stat")).select_by_value("gap")
    assert "a1" in driver.find_element(By.ID, "main-title").text
    assert len(driver.find_elements(By.CSS_SELECTOR, "#modes-grid canvas")) == 12
    # Leave a target marked for the screenshot.
    box = driver.find_element(By.ID, "target")
    box.clear()
    box.send_keys("x=10,y=50,a0=0.015,a1=-0.07,a2=-0.03", Keys.ENTER)
    Select(driver.find_element(By.ID, "coef")).select_by_value("0")
    Select(driver.find_element(By.ID, "stat")).select_by_value("count")
    screenshot.parent.mkdir(parents=True, exist_ok=True)
    driver.execute_script("window.scrollTo(0, 0);")
    driver.set_window_size(1400, 2400)
    assert driver.save_screenshot(str(screenshot)), screenshot


try:
    run_check("explorer: loads from file:// with the actuator header", check_loads)
    run_check("explorer: hover shows the cell's numbers from cells.parquet", check_hover)
    run_check("explorer: click lists the cell's stored designs from designs.parquet", check_click)
    run_check("explorer: typed targets get the verdict of `cablemap feasible`", check_targets)
    run_check("explorer: coefficient and statistic controls, 12 mode panels, screenshot", check_controls)
finally:
    driver.quit()
print(f"screenshot: {screenshot}")
sys.exit(finish())
