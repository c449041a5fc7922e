"""What the console's browser test and benchmark share: a covplan-server
started on free ports with a store of its own (and its JSON API), and a
headless Debian Chromium driven by Selenium through chromedriver.

  server = Server("build/bin/covplan-server")
  server.call("ListMaps", {})          # POST /v1/ListMaps
  driver = chromium()                  # None-safe check: missing_tools()
"""
import json
import os
import shutil
import socket
import subprocess
import tempfile
import time
import urllib.error
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SKIP = 77
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
except ImportError:  # see missing_tools()
    webdriver = None


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    """covplan-server on free ports with a store of its own."""

    def __init__(self, binary):
        self.dir = tempfile.mkdtemp(prefix="covplan-console-")
        self.grpc_port, self.http_port = free_port(), free_port()
        self.log = open(os.path.join(self.dir, "server.log"), "w+")
        self.proc = subprocess.Popen(
            [binary, f"--port={self.grpc_port}", "--metrics_port=-1",
             f"--http_port={self.http_port}", f"--store_dir={self.dir}/maps", "--threads=2"],
            stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + 60
        while True:
            if self.proc.poll() is not None:
                raise RuntimeError("covplan-server exited: " + self.output())
            try:
                self.call("ListMaps", {})
                return
            except (urllib.error.URLError, ConnectionError):
                if time.monotonic() > deadline:
                    raise RuntimeError("covplan-server did not answer: " + self.output())
                time.sleep(0.2)

    @property
    def url(self):
        return f"http://127.0.0.1:{self.http_port}/"

    def call(self, method, body):
        request = urllib.request.Request(
            f"{self.url}v1/{method}", data=json.dumps(body).encode(),
            headers={"Content-Type": "application/json"}, method="POST")
        with urllib.request.urlopen(request, timeout=60) as reply:
            return json.load(reply)

    def output(self):
        self.log.seek(0)
        return self.log.read()[-4000:]

    def stop(self):
        self.proc.terminate()
        try:
            code = self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)
        return code


def chromium():
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,900", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)


def screenshot_pixels(driver):
    """The page's screenshot as (width, height, rgb bytes), decoded with
    Chromium itself (no imaging package needed): a canvas in the page."""
    png = driver.get_screenshot_as_base64()
    return driver.execute_async_script(
        """
        const [png, done] = arguments;
        const img = new Image();
        img.onload = () => {
          const c = document.createElement('canvas');
          c.width = img.width; c.height = img.height;
          const g = c.getContext('2d');
          g.drawImage(img, 0, 0);
          const d = g.getImageData(0, 0, c.width, c.height).data;
          done({w: c.width, h: c.height, rgba: Array.from(d)});
        };
        img.src = 'data:image/png;base64,' + png;
        """, png)




def missing_tools():
    """The Debian packages the browser needs that are not installed."""
    return [what for what, ok in (("python3-selenium", webdriver is not None),
                                  ("chromium", os.access(CHROMIUM, os.X_OK)),
                                  ("chromium-driver", os.access(CHROMEDRIVER, os.X_OK))) if not ok]
