#!/usr/bin/python3
"""The web console's speed in a real browser (headless Debian Chromium):

1. a plan of about 5,000 ranks (a generated 57 m x 57 m hall with a pillar
   every fourth 0.2 m cell, tool 0.2 m) planned from the page: the time from
   the response in hand to its DOM built (drawMs) and to the frame after the
   one that painted it (paintMs), median of --repeat plans;
2. ROBOTS robots simulated through the server (covplan simulate --watch,
   each reporting up to 20 times a second) watched on one map for SECONDS:
   per robot the marker updates per second the page applied, and the lag from
   the server seeing a report to the page drawing it (sampled every 100 ms).

  /usr/bin/python3 scripts/bench/console_bench.py --server build/bin/covplan-server \\
      --client build/bin/covplan [--robots 8] [--seconds 20] [--repeat 3]
"""
import argparse
import base64
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "tests", "console"))
from harness import ROOT, Server, chromium, missing_tools  # noqa: E402

if not missing_tools():
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait


def pillar_hall(metres=57.0, step=4):
    """A PGM (bytes) of a walled square hall, one 0.2 m pillar every `step` cells."""
    w = h = int(metres / 0.05)
    px = bytearray([254]) * (w * h)
    for y in range(h):
        for x in range(w):
            if x < 4 or y < 4 or x >= w - 4 or y >= h - 4:
                px[y * w + x] = 0
    for cy in range(2, h // 4 - 2, step):
        for cx in range(2 + (cy // step) % 2 * (step // 2), w // 4 - 2, step):
            for y in range(cy * 4, cy * 4 + 4):
                px[y * w + cx * 4:y * w + cx * 4 + 4] = b"\0\0\0\0"
    return b"P5\n%d %d\n255\n" % (w, h) + bytes(px)


def open_map(driver, server, map_id):
    driver.get(server.url)
    WebDriverWait(driver, 60).until(
        lambda d: d.find_elements(By.CSS_SELECTOR, f'li[data-map-id="{map_id}"]'))
    driver.find_element(By.CSS_SELECTOR, f'li[data-map-id="{map_id}"]').click()
    WebDriverWait(driver, 60).until(lambda d: d.find_element(By.ID, "plan-form").is_displayed())


def big_plan(driver, server, repeat):
    yaml = "resolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n" \
           "free_thresh: 0.196\nmode: trinary\nimage: hall.pgm\n"
    image = base64.b64encode(pillar_hall()).decode()
    info = server.call("PutMap", {"name": "pillar hall",
                                  "map": {"raster": {"image": image, "yaml": yaml}}})["info"]
    open_map(driver, server, info["mapId"])
    width = driver.find_element(By.ID, "tool-width")
    width.clear()
    width.send_keys("0.2")
    limit = driver.find_element(By.ID, "time-limit")
    limit.clear()
    limit.send_keys("3")
    Select(driver.find_element(By.ID, "planner")).select_by_value("oarp")
    draws, paints, ranks = [], [], 0
    for _ in range(repeat):
        # (A repeated request may be answered with the remembered plan: it is
        # drawn all the same.)
        driver.execute_script("delete document.getElementById('view').dataset.paintMs")
        driver.find_element(By.ID, "plan-button").click()
        WebDriverWait(driver, 300).until(
            lambda d: d.find_element(By.ID, "view").get_attribute("data-paint-ms"))
        view = driver.find_element(By.ID, "view")
        draws.append(float(view.get_attribute("data-draw-ms")))
        paints.append(float(view.get_attribute("data-paint-ms")))
        ranks = len(driver.find_elements(By.CSS_SELECTOR, "#ranks line.rank"))
    return ranks, statistics.median(draws), statistics.median(paints), max(paints)


def watched_robots(driver, server, client, robots, seconds):
    sims = []
    known = os.path.join(ROOT, "maps", "small_rooms.yaml")
    try:
        for k in range(robots):
            sims.append(subprocess.Popen(
                [client, "simulate", "--map", known, "--true-map", known, "--seed", str(k + 1),
                 "--tool-width", "0.4", "--server", f"127.0.0.1:{server.grpc_port}", "--watch", "4"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 60
        map_id = None
        while map_id is None and time.monotonic() < deadline:
            maps = [m for m in server.call("ListMaps", {}).get("maps", [])
                    if m.get("widthPx") == 200]
            map_id = maps[0]["mapId"] if maps else None
            time.sleep(0.2)
        open_map(driver, server, map_id)
        WebDriverWait(driver, 60).until(
            lambda d: len(d.find_elements(By.CSS_SELECTOR, "#live circle.robot")) >= robots)
        read = ("return [...document.querySelectorAll('#live circle.robot')].map("
                "(m) => [Number(m.dataset.moves), Number(m.dataset.time || 0), Date.now() / 1000]);")
        first = driver.execute_script(read)
        t0 = time.monotonic()
        lags = []
        while time.monotonic() - t0 < seconds:
            for _, seen, now in driver.execute_script(read):
                if seen > 0:
                    lags.append(now - seen)
            time.sleep(0.1)
        last = driver.execute_script(read)
        took = time.monotonic() - t0
        rates = [(b[0] - a[0]) / took for a, b in zip(first, last)]
        return rates, lags
    finally:
        for s in sims:
            s.kill()
            s.wait()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True)
    parser.add_argument("--client", required=True)
    parser.add_argument("--robots", type=int, default=8)
    parser.add_argument("--seconds", type=float, default=20)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    if missing_tools():
        sys.exit("console_bench: missing " + ", ".join(missing_tools()))
    server = Server(args.server)
    driver = chromium()
    try:
        ranks, draw, paint, worst = big_plan(driver, server, args.repeat)
        print(f"plan of {ranks} ranks: drawn (DOM) {draw:.0f} ms, painted {paint:.0f} ms "
              f"(median of {args.repeat}; slowest {worst:.0f} ms)")
        rates, lags = watched_robots(driver, server, args.client, args.robots, args.seconds)
        lags.sort()
        print(f"{args.robots} robots watched {args.seconds:.0f} s: updates per robot per second "
              f"min {min(rates):.1f}, median {statistics.median(rates):.1f}; lag server->page "
              f"median {1000 * lags[len(lags) // 2]:.0f} ms, p95 {1000 * lags[int(0.95 * len(lags))]:.0f} ms")
    finally:
        driver.quit()
        server.stop()


if __name__ == "__main__":
    main()
