// The live view of the open map: the robots driving on it, as the server's
// event stream (GET /v1/events?map_id=..., Server-Sent Events of
// covplan.v1.LiveEvent) reports them. Each robot (a Drive session) gets a
// colour, a marker at its last reported position, the area it swept (its
// track drawn a tool width wide), its current plan (fetched with GetPlan
// when it starts or gets a new plan), the obstacles it reported, and a line
// in the panel: progress along its plan and an estimate of the time left.
// Replans and ends go into the log with what changed, the method and how
// long the server took.
//
//   const live = createLiveView({ api, svgEl, token: () => state.token });
//   live.watch(mapId);   // stops watching the previous map
//
// The stream is read with fetch (EventSource cannot send the bearer token)
// and reconnects after a dropped connection.

const COLOURS = ['#cf222e', '#1a7f37', '#8250df', '#bc4c00', '#0550ae', '#bf3989', '#116329', '#953800'];
const $ = (id) => document.getElementById(id);

// A stream the server refused for good (401, 403, 404): not retried.
class Refused extends Error {}

const MAX_TRACK_POINTS = 5000;  // per robot; older points are thinned out

export function createLiveView({ api, svgEl, token, setStatus }) {
  let controller = null;
  let robots = new Map();  // session id -> robot
  let mapId = null;

  function robotOf(e) {
    let r = robots.get(e.sessionId);
    if (r) return r;
    const colour = COLOURS[robots.size % COLOURS.length];
    const g = svgEl('g', { class: 'live-robot', 'data-session': e.sessionId });
    const trail = svgEl('polyline', { class: 'live-trail', stroke: colour, points: '' });
    const plan = svgEl('polyline', { class: 'live-plan', stroke: colour, points: '' });
    const obstacles = svgEl('g', { class: 'live-obstacles' });
    const marker = svgEl('circle', { class: 'robot', r: 0.35, fill: colour, 'data-moves': 0 });
    g.append(plan, trail, obstacles, marker);
    $('live').append(g);
    const row = document.createElement('li');
    row.dataset.session = e.sessionId;
    row.style.borderLeftColor = colour;
    $('live-robots').append(row);
    r = { id: e.robotId || e.sessionId, colour, g, trail, plan, obstacles, marker, row,
          points: [], planId: null, path: null, grid: null, duration: 0, ended: false };
    robots.set(e.sessionId, r);
    $('live-panel').hidden = false;
    return r;
  }

  async function loadPlan(r, planId) {
    if (!planId || r.planId === planId) return;
    r.planId = planId;
    const p = await api('GetPlan', { planId });
    if (r.planId !== planId) return;  // a newer plan came meanwhile
    r.path = p.path;
    r.grid = p.grid;
    r.duration = p.stats.estimatedDurationS || 0;
    r.plan.setAttribute('points', p.path.map((w) => `${w.x || 0},${w.y || 0}`).join(' '));
    r.g.dataset.planId = planId;  // the plan drawn
    r.trail.setAttribute('stroke-width', p.grid.cellSizeM);
    showRow(r, null);
  }

  function showRow(r, progress) {
    const n = r.path ? r.path.length - 1 : 0;
    const k = progress ? Math.min(progress.waypoint || 0, n) : 0;
    const done = n > 0 ? k / n : 0;
    const left = r.duration * (1 - done);
    r.row.textContent = r.ended
      ? `${r.id}: ended`
      : `${r.id}: ${(100 * done).toFixed(0)} % of its plan, about ${left.toFixed(0)} s left`;
    r.row.dataset.progress = done.toFixed(3);
  }

  function logLine(kind, text) {
    const li = document.createElement('li');
    li.dataset.kind = kind;
    li.textContent = `${new Date().toLocaleTimeString()} ${text}`;
    $('live-log').prepend(li);
    while ($('live-log').children.length > 200) $('live-log').lastChild.remove();
  }

  function drawObstacles(r, o) {
    const g = r.grid;
    for (const c of o.cells || []) {
      if (!g) break;
      r.obstacles.append(svgEl('rect', {
        class: 'live-obstacle', x: g.originXM + (c.col || 0) * g.cellSizeM,
        y: g.originYM + (c.row || 0) * g.cellSizeM, width: g.cellSizeM, height: g.cellSizeM,
      }));
    }
    for (const p of o.points || []) {
      r.obstacles.append(svgEl('circle', { class: 'live-obstacle', cx: p.x || 0, cy: p.y || 0, r: 0.15 }));
    }
  }

  function handle(e) {
    const r = robotOf(e);
    if (e.started !== undefined || (e.progress && !r.planId)) loadPlan(r, e.planId).catch(() => {});
    if (e.progress && e.progress.position) {
      const { x = 0, y = 0 } = e.progress.position;
      r.marker.setAttribute('cx', x);
      r.marker.setAttribute('cy', y);
      r.marker.dataset.moves = Number(r.marker.dataset.moves) + 1;
      r.marker.dataset.time = e.timeUnixS;  // when the server saw it (lag = now - this)
      const last = r.points[r.points.length - 1];
      if (!last || Math.hypot(last[0] - x, last[1] - y) > 0.02) r.points.push([x, y]);
      if (r.points.length > MAX_TRACK_POINTS) r.points = r.points.filter((_, i) => i % 2 === 0);
      r.trail.setAttribute('points', r.points.map((p) => p.join(',')).join(' '));
      showRow(r, e.progress);
    }
    if (e.obstacles) {
      drawObstacles(r, e.obstacles);
      const n = (e.obstacles.cells || []).length + (e.obstacles.points || []).length;
      logLine('obstacles', `${r.id} reported ${n} obstacle item(s)`);
    }
    if (e.replan) {
      const s = e.replan.replan || {};
      const why = e.replan.mission && e.replan.mission.cause === 'SHARED_OBSTACLE'
        ? ` (obstacle seen by ${e.replan.mission.fromRobot})`
        : e.replan.mission ? ' (mission redivided)' : '';
      logLine('replan', `${r.id} replanned${why}: ${s.method || '?'}, ${(e.replan.computeMs || 0).toFixed(0)} ms, `
        + `${s.numEncounters || 0} encounters, ${s.newRanks || 0} new / ${s.keptRanks || 0} kept ranks`);
      loadPlan(r, e.planId).catch(() => {});
    }
    if (e.ended) {
      r.ended = true;
      r.g.classList.add('ended');
      showRow(r, null);
      logLine('ended', `${r.id} ended (${e.ended.status})`);
    }
  }

  async function read(id, signal) {
    const headers = {};
    if (token()) headers.Authorization = `Bearer ${token()}`;
    const reply = await fetch(`/v1/events?map_id=${encodeURIComponent(id)}`, { headers, signal });
    if ([401, 403, 404].includes(reply.status)) {
      const body = await reply.json().catch(() => ({}));
      throw new Refused(`live events: ${body.status || reply.status}: ${body.message || ''}`);
    }
    if (!reply.ok) throw new Error(`live events: HTTP ${reply.status}`);
    const reader = reply.body.pipeThrough(new TextDecoderStream()).getReader();
    let buffer = '';
    try {
      for (;;) {
        const { value, done } = await reader.read();
        if (done) return;
        buffer = (buffer + value).replace(/\r\n?/g, '\n');
        let end;
        while ((end = buffer.indexOf('\n\n')) >= 0) {
          const block = buffer.slice(0, end);
          buffer = buffer.slice(end + 2);
          for (const line of block.split('\n')) {
            if (line.startsWith('data: ')) handle(JSON.parse(line.slice(6)));
          }
        }
      }
    } finally {
      reader.cancel().catch(() => {});
    }
  }

  function watch(id) {
    if (controller) controller.abort();
    robots = new Map();
    mapId = id;
    $('live').replaceChildren();
    $('live-robots').replaceChildren();
    $('live-log').replaceChildren();
    $('live-panel').hidden = true;
    controller = new AbortController();
    const signal = controller.signal;
    const loop = async () => {
      while (!signal.aborted && mapId === id) {
        try {
          await read(id, signal);
        } catch (err) {
          if (signal.aborted) return;
          if (err instanceof Refused) {
            setStatus(err.message, true);
            return;
          }
        }
        await new Promise((resolve) => setTimeout(resolve, 2000));  // then reconnect
      }
    };
    loop();
  }

  return { watch };
}
