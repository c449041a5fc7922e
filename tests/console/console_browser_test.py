#!/usr/bin/python3
"""The web console in a real browser: Debian's Chromium, headless, driven by
Selenium through chromedriver, against a covplan-server started here with its
JSON API on (--http_port).

What the page shows is checked against what the JSON API returns for the same
plan id: one line per rank, the path's polyline point for point, the figures;
and on the pixels of a screenshot (the rank lines change the picture where
they are drawn). A no-go zone drawn with the mouse reaches the planner: the
plan drawn keeps its coverage out of it, where the plan without it swept
through. Bad input shows the server's INVALID_ARGUMENT message and adds no map.
A robot simulated through the server (covplan simulate --server --watch) is
seen live: its marker moves at least five times and a replan appears in the
log. Each step leaves a screenshot in --artifacts.

  /usr/bin/python3 tests/console/console_browser_test.py --server build/bin/covplan-server \
      --client build/bin/covplan --artifacts /tmp/console-shots

Exit code 77 (ctest: skipped) when Chromium, chromedriver or Selenium are
missing and CI is not set; under CI=true they are required (install-deps).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
import unittest

from harness import (ROOT, SKIP, Server, chromium, missing_tools, screenshot_pixels, webdriver)

if webdriver is not None:
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

ARGS = None


def cell_centre(grid, cell):
    """The centre of `cell` (an API CellRef) on `grid` (an API GridInfo), as (x, y)."""
    size = grid["cellSizeM"]
    return (grid.get("originXM", 0.0) + (cell.get("col", 0) + 0.5) * size,
            grid.get("originYM", 0.0) + (cell.get("row", 0) + 0.5) * size)


def segments_inside(path, box, margin):
    """The coverage moves of `path` (API waypoints) that pass through the
    rectangle `box` (x0, y0, x1, y1) shrunk by `margin`, sampled every 2 cm."""
    x0, y0, x1, y1 = box[0] + margin, box[1] + margin, box[2] - margin, box[3] - margin
    hits = []
    for i in range(1, len(path)):
        if path[i].get("kind", "COVERAGE") != "COVERAGE":
            continue
        a, b = path[i - 1], path[i]
        ax, ay, bx, by = a.get("x", 0.0), a.get("y", 0.0), b.get("x", 0.0), b.get("y", 0.0)
        n = max(1, int(((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5 / 0.02))
        for k in range(n + 1):
            x, y = ax + (bx - ax) * k / n, ay + (by - ay) * k / n
            if x0 < x < x1 and y0 < y < y1:
                hits.append(i)
                break
    return hits


class Browser(unittest.TestCase):
    """A server and a headless Chromium for the test cases below (no tests of its own)."""

    @classmethod
    def setUpClass(cls):
        cls.server = Server(ARGS.server)
        cls.driver = chromium()
        cls.driver.set_script_timeout(60)
        cls.wait = WebDriverWait(cls.driver, 60)

    @classmethod
    def tearDownClass(cls):
        cls.driver.quit()
        code = cls.server.stop()
        if code != 0:
            raise AssertionError(f"covplan-server exited with {code}")

    def shot(self, name):
        """A screenshot of this step, kept as a test artefact."""
        os.makedirs(ARGS.artifacts, exist_ok=True)
        self.driver.save_screenshot(os.path.join(ARGS.artifacts, name + ".png"))

    def by_id(self, name):
        return self.driver.find_element(By.ID, name)

    def status(self):
        return self.by_id("status").text

    def open_console(self):
        self.driver.get(self.server.url)
        self.wait.until(lambda d: d.find_element(By.ID, "status").text.endswith("maps"))

    def upload_office(self):
        """Uploads the shipped office (PGM + YAML) with the page's own form."""
        self.open_console()
        before = len(self.server.call("ListMaps", {}).get("maps", []))
        self.driver.execute_script("document.getElementById('upload').open = true")
        self.by_id("upload-image").send_keys(os.path.join(ROOT, "maps", "sample_office.pgm"))
        self.by_id("upload-yaml").send_keys(os.path.join(ROOT, "maps", "sample_office.yaml"))
        name = self.by_id("upload-name")
        name.clear()
        name.send_keys("office")
        self.by_id("upload-button").click()
        self.wait.until(lambda d: d.find_element(By.ID, "plan-form").is_displayed())
        maps = self.server.call("ListMaps", {})["maps"]
        self.assertGreaterEqual(len(maps), max(1, before))
        return [m for m in maps if m.get("name") == "office"][0]

    def plan(self, previous=None):
        self.by_id("plan-button").click()
        try:
            self.wait.until(lambda d: d.find_element(By.ID, "view").get_attribute("data-plan-id")
                            not in (None, "", previous))
        except TimeoutException:
            self.fail("no plan drawn; status: " + self.status())
        plan_id = self.by_id("view").get_attribute("data-plan-id")
        return self.server.call("GetPlan", {"planId": plan_id})

    def drawn_path(self):
        points = self.driver.find_element(By.CSS_SELECTOR, "#transitions polyline.path")
        return [tuple(float(v) for v in p.split(","))
                for p in points.get_attribute("points").split()]



class ConsoleInTheBrowser(Browser):
    """Maps, plans, zones and errors on the page against the JSON API."""

    def test_the_page_draws_the_plan_the_api_returns(self):
        office = self.upload_office()
        self.assertIn("map", self.status())
        self.shot("1_map_open")
        plan = self.plan()
        self.shot("2_plan_drawn")
        self.assertEqual(plan["mapId"], office["mapId"])
        ranks = plan.get("ranks", [])
        num_ranks = int(plan["stats"]["numRanks"])
        self.assertGreater(num_ranks, 0)
        self.assertEqual(len(ranks), num_ranks)
        lines = self.driver.find_elements(By.CSS_SELECTOR, "#ranks line.rank")
        self.assertEqual(len(lines), num_ranks)
        # Each rank line runs between the centres of its first and last cells.
        for line, rank in zip(lines, ranks):
            want = cell_centre(plan["grid"], rank["firstCell"]) + cell_centre(plan["grid"], rank["lastCell"])
            got = tuple(float(line.get_attribute(k)) for k in ("x1", "y1", "x2", "y2"))
            for w, v in zip(want, got):
                self.assertAlmostEqual(w, v, places=6)
        # The path, point for point.
        drawn = self.drawn_path()
        self.assertEqual(len(drawn), len(plan["path"]))
        for (x, y), w in zip(drawn, plan["path"]):
            self.assertAlmostEqual(x, w.get("x", 0.0), places=6)
            self.assertAlmostEqual(y, w.get("y", 0.0), places=6)
        # The figures.
        figures = {dd.get_attribute("data-figure"): dd.text
                   for dd in self.driver.find_elements(By.CSS_SELECTOR, "#figure-list dd")}
        self.assertEqual(figures["Ranks"], str(num_ranks))
        self.assertEqual(figures["Planner"], plan["planner"])
        self.assertEqual(figures["Duration"], f"{plan['stats']['estimatedDurationS']:.0f} s")
        self.assertTrue(plan["planId"].startswith(figures["Plan"]))
        # On the pixels: hiding the ranks changes the picture at each rank's
        # middle (where no other line of the plan needs to be).
        middles = self.driver.execute_script(
            """
            const svg = document.getElementById('view');
            const box = svg.getBoundingClientRect();
            return [...document.querySelectorAll('#ranks line.rank')].map((l) => {
              const m = l.getScreenCTM();
              const x = (Number(l.getAttribute('x1')) + Number(l.getAttribute('x2'))) / 2;
              const y = (Number(l.getAttribute('y1')) + Number(l.getAttribute('y2'))) / 2;
              const p = new DOMPoint(x, y).matrixTransform(m);
              return [Math.round(p.x), Math.round(p.y), p.x >= box.left && p.x < box.right &&
                      p.y >= box.top && p.y < box.bottom];
            });
            """)
        visible = [(x, y) for x, y, inside in middles if inside]
        self.assertGreater(len(visible), num_ranks // 2, "most rank middles are in the view")
        shown = screenshot_pixels(self.driver)
        self.driver.execute_script("document.getElementById('ranks').style.display = 'none'")
        hidden = screenshot_pixels(self.driver)
        self.driver.execute_script("document.getElementById('ranks').style.display = ''")
        self.assertEqual((shown["w"], shown["h"]), (hidden["w"], hidden["h"]))

        def differs(x, y):  # any pixel within 1 px of (x, y)
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    i = 4 * ((y + dy) * shown["w"] + (x + dx))
                    if shown["rgba"][i:i + 3] != hidden["rgba"][i:i + 3]:
                        return True
            return False

        drawn_ranks = sum(1 for x, y in visible if differs(x, y))
        print(f"\n  {num_ranks} ranks drawn, {len(plan['path'])} waypoints; {drawn_ranks} of "
              f"{len(visible)} rank middles in view change the picture", file=sys.stderr)
        self.assertEqual(drawn_ranks, len(visible), "rank lines missing from the picture")

    def test_a_no_go_zone_drawn_with_the_mouse_keeps_the_coverage_out(self):
        self.upload_office()
        free_plan = self.plan()
        # The zone: a square three cells wide around the middle of the
        # longest rank (in the plan's frame), entered by clicks at its
        # corners' screen points.
        g = free_plan["grid"]
        size = g["cellSizeM"]

        def length(r):
            (ax, ay), (bx, by) = cell_centre(g, r["firstCell"]), cell_centre(g, r["lastCell"])
            return abs(bx - ax) + abs(by - ay)

        longest = max(free_plan["ranks"], key=length)
        (ax, ay), (bx, by) = cell_centre(g, longest["firstCell"]), cell_centre(g, longest["lastCell"])
        cx, cy = (ax + bx) / 2, (ay + by) / 2
        half = 1.5 * size
        corners = [(cx - half, cy - half), (cx + half, cy - half), (cx + half, cy + half),
                   (cx - half, cy + half)]
        self.assertTrue(segments_inside(free_plan["path"], (cx - half, cy - half, cx + half, cy + half),
                                        0.0), "the plan without the zone sweeps through it")
        self.by_id("draw-nogo").click()
        view = self.by_id("view")
        box = self.driver.execute_script(
            "const r = arguments[0].getBoundingClientRect(); return [r.left, r.top, r.width, r.height];",
            view)
        for x, y in corners:
            px, py = self.driver.execute_script(
                """
                const p = new DOMPoint(arguments[0], arguments[1])
                    .matrixTransform(document.getElementById('world').getScreenCTM());
                return [p.x, p.y];
                """, x, y)
            # Offsets from the element's centre (Selenium 4's reference point).
            ActionChains(self.driver).move_to_element_with_offset(
                view, int(round(px - box[0] - box[2] / 2)), int(round(py - box[1] - box[3] / 2))
            ).click().perform()
        self.by_id("finish-zone").click()
        zone = self.driver.find_element(By.CSS_SELECTOR, "#zones polygon")
        points = [tuple(float(v) for v in p.split(",")) for p in zone.get_attribute("points").split()]
        self.assertEqual(len(points), 4)
        xs, ys = [p[0] for p in points], [p[1] for p in points]
        # The clicks land within a pixel of the corners.
        self.assertAlmostEqual(min(xs), cx - half, delta=0.1)
        self.assertAlmostEqual(max(ys), cy + half, delta=0.1)
        zoned = self.plan(previous=free_plan["planId"])
        self.shot("3_no_go_zone_planned")
        # Nothing swept inside the zone (a tool half-width from its edges),
        # and fewer cells covered than without it.
        inside = segments_inside(zoned["path"], (min(xs), min(ys), max(xs), max(ys)),
                                 zoned["grid"]["cellSizeM"] / 2)
        print(f"\n  zone ({min(xs):.2f}, {min(ys):.2f})-({max(xs):.2f}, {max(ys):.2f}): "
              f"{len(segments_inside(free_plan['path'], (min(xs), min(ys), max(xs), max(ys)), 0.0))} "
              f"coverage moves through it without the zone, {len(inside)} with it; covered cells "
              f"{free_plan['stats']['coveredCells']} -> {zoned['stats']['coveredCells']} (closed "
              f"{zoned['stats'].get('noGoCells', 0)}, cut off {zoned['stats'].get('unreachableFreeCells', 0)})", file=sys.stderr)
        self.assertEqual(inside, [], "coverage moves through the drawn no-go zone")
        # Every cell is accounted for: covered, closed by the zone, or cut
        # off by it (on the office the square closes the corridor).
        zs, fs = zoned["stats"], free_plan["stats"]
        self.assertGreater(zs.get("noGoCells", 0), 0)
        self.assertLess(zs["coveredCells"], fs["coveredCells"])
        self.assertEqual(zs["coveredCells"] + zs.get("noGoCells", 0) + zs.get("unreachableFreeCells", 0),
                         fs["coveredCells"] + fs.get("unreachableFreeCells", 0))

    def test_bad_input_shows_the_servers_message_and_adds_no_map(self):
        self.open_console()
        before = self.server.call("ListMaps", {}).get("maps", [])
        bad = os.path.join(self.server.dir, "not_an_image.png")
        with open(bad, "wb") as f:
            f.write(b"this is not a PNG")
        self.driver.execute_script("document.getElementById('upload').open = true")
        self.driver.execute_script(
            "for (const id of ['upload-yaml', 'upload-image', 'upload-geojson'])"
            " document.getElementById(id).value = '';")
        self.by_id("upload-image").send_keys(bad)
        self.by_id("upload-button").click()
        self.wait.until(lambda d: "error" in (d.find_element(By.ID, "status").get_attribute("class") or ""))
        self.assertIn("INVALID_ARGUMENT", self.status())
        self.shot("4_bad_upload")
        self.assertEqual(self.server.call("ListMaps", {}).get("maps", []), before)


class LiveRobotInTheBrowser(Browser):
    """The live view, against a robot simulated through the same server."""

    def test_a_robot_driving_through_the_server_is_seen_live(self):
        before = {m["mapId"] for m in self.server.call("ListMaps", {}).get("maps", [])}
        log = open(os.path.join(self.server.dir, "simulate.log"), "w+")
        sim = subprocess.Popen(
            [ARGS.client, "simulate", "--map", os.path.join(ROOT, "maps", "small_rooms.yaml"),
             "--clutter", "5", "--seed", "3", "--server", f"127.0.0.1:{self.server.grpc_port}",
             "--watch", "5"], stdout=log, stderr=subprocess.STDOUT)
        try:
            map_id = None
            deadline = time.monotonic() + 60
            while map_id is None and time.monotonic() < deadline and sim.poll() is None:
                new = [m["mapId"] for m in self.server.call("ListMaps", {}).get("maps", [])
                       if m["mapId"] not in before]
                map_id = new[0] if new else None
                time.sleep(0.2)
            log.seek(0)
            self.assertIsNotNone(map_id, "simulate stored no map: " + log.read()[-2000:])
            self.open_console()
            self.driver.find_element(By.CSS_SELECTOR, f'li[data-map-id="{map_id}"]').click()
            self.wait.until(lambda d: d.find_element(By.ID, "plan-form").is_displayed())
            # The marker moves: five different positions, each a reported one.
            positions = []
            deadline = time.monotonic() + 60
            while len(set(positions)) < 5 and time.monotonic() < deadline:
                markers = self.driver.find_elements(By.CSS_SELECTOR, "#live circle.robot")
                if markers and markers[0].get_attribute("cx") is not None:
                    positions.append((markers[0].get_attribute("cx"), markers[0].get_attribute("cy")))
                time.sleep(0.15)
            self.assertGreaterEqual(len(set(positions)), 5, f"the marker sat at {set(positions)}")
            info = self.server.call("GetMap", {"mapId": map_id})["info"]
            x0, y0 = info.get("originXM", 0.0), info.get("originYM", 0.0)
            w, h = info["widthPx"] * info["resolution"], info["heightPx"] * info["resolution"]
            for cx, cy in set(positions):
                self.assertTrue(x0 <= float(cx) <= x0 + w and y0 <= float(cy) <= y0 + h, (cx, cy))
            self.shot("5_live_robot")
            # A replan (the clutter is found) shows in the log, with its method.
            try:
                WebDriverWait(self.driver, 90).until(lambda d: d.find_elements(
                    By.CSS_SELECTOR, '#live-log li[data-kind="replan"]'))
            except TimeoutException:
                log.seek(0)
                self.fail("no replan shown; simulate: " + log.read()[-2000:])
            entry = self.driver.find_element(By.CSS_SELECTOR, '#live-log li[data-kind="replan"]').text
            self.assertRegex(entry, r"replanned.*: (auto/)?[a-z0-9_]+, \d+ ms, \d+ encounters")
            rows = self.driver.find_elements(By.CSS_SELECTOR, "#live-robots li")
            self.assertEqual(len(rows), 1)
            self.assertRegex(rows[0].text, r"\d+ % of its plan, about \d+ s left")
            # The robot's plan drawn is the one the API holds under the id it shows.
            WebDriverWait(self.driver, 30).until(lambda d: d.find_element(
                By.CSS_SELECTOR, "#live g.live-robot").get_attribute("data-plan-id"))
            robot = self.driver.find_element(By.CSS_SELECTOR, "#live g.live-robot")
            shown = robot.get_attribute("data-plan-id")
            drawn = [tuple(float(v) for v in p.split(",")) for p in robot.find_element(
                By.CSS_SELECTOR, "polyline.live-plan").get_attribute("points").split()]
            path = self.server.call("GetPlan", {"planId": shown})["path"]
            self.assertEqual(len(drawn), len(path))
            for (x, y), w in zip(drawn, path):
                self.assertAlmostEqual(x, w.get("x", 0.0), places=6)
                self.assertAlmostEqual(y, w.get("y", 0.0), places=6)
            left = int(rows[0].text.split("about ")[1].split(" s")[0])
            self.assertGreater(left, 0, "the time left needs the plan's duration")
            self.shot("6_live_replan")
            print(f"\n  marker at {len(set(positions))} positions; log: {entry}", file=sys.stderr)
        finally:
            sim.kill()
            sim.wait()
            log.close()


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    parser.add_argument("--server", required=True, help="the covplan-server binary")
    parser.add_argument("--client", required=True, help="the covplan binary (simulate --watch)")
    parser.add_argument("--artifacts", default=os.path.join(tempfile.gettempdir(), "covplan-console"),
                        help="where each step's screenshot goes")
    ARGS, rest = parser.parse_known_args()
    missing = missing_tools()
    if missing:
        print("console browser test: missing " + ", ".join(missing) + " (scripts/install-deps.sh)")
        return 1 if os.environ.get("CI") == "true" else SKIP
    program = unittest.main(argv=[sys.argv[0]] + rest, exit=False, verbosity=2)
    return 0 if program.result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())
