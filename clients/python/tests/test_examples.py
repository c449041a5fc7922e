"""The examples run against the test server and do what they say."""
import json
import os
import subprocess
import sys

from conftest import MAPS, ROOT

EXAMPLES = os.path.join(ROOT, "clients", "python", "examples")


def run(script, *args):
    result = subprocess.run([sys.executable, os.path.join(EXAMPLES, script), *args],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_plan_map_writes_json_and_svg(server, tmp_path):
    out = tmp_path / "office"
    text = run("plan_map.py", "--server", server.address, "--map",
               os.path.join(MAPS, "sample_office.yaml"), "--out", str(out))
    plan = json.loads(out.with_suffix(".json").read_text())
    assert plan["plan_id"] in text
    assert out.with_suffix(".svg").read_text().startswith("<svg")
    geojson = json.loads(out.with_suffix(".geojson").read_text())
    assert len(geojson["features"][0]["geometry"]["coordinates"]) == len(plan["path"])
    assert len(out.with_suffix(".csv").read_text().splitlines()) == len(plan["path"]) + 1
    nav = json.loads(out.with_suffix(".nav_path.json").read_text())
    assert len(nav["poses"]) == len(plan["path"])


def test_drive_robot_meets_an_obstacle_and_finishes(server):
    text = run("drive_robot.py", "--server", server.address, "--map",
               os.path.join(MAPS, "sample_office.yaml"))
    assert "replanned by" in text and "obstacle met" in text
