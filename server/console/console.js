// The covplan web console: the caller's maps, a map view with pan and zoom,
// zones drawn on the map, a plan made from the page and drawn with its
// figures. It speaks only the JSON API of the server that serves it
// (POST /v1/<Method>, protobuf's JSON mapping of covplan.v1).
//
// The view is one SVG in map metres: #scene holds the map image (SVG's y
// axis points down, so a map point (x, y) sits at (x, -y)); #world inside it
// flips y, so every vector layer is drawn in plain map coordinates.

import { createLiveView } from './live.js';

const $ = (id) => document.getElementById(id);
const SVG_NS = 'http://www.w3.org/2000/svg';

const state = {
  token: sessionStorage.getItem('covplan.token') || '',
  info: null,          // MapInfo of the open map
  zones: [],           // {kind: 'nogo' | 'region', points: [[x, y], ...]} (open rings)
  drawing: null,       // the zone being drawn
  plan: null,          // the last PlanResponse
  box: null,           // the SVG viewBox [x, y, w, h]
};

class ApiError extends Error {
  constructor(status, message, http) {
    super(`${status}: ${message}`);
    this.status = status;
    this.http = http;
  }
}

function setStatus(text, isError = false) {
  const s = $('status');
  s.textContent = text;
  s.classList.toggle('error', isError);
}

// Asks for a token in the dialog; resolves once one is entered.
function askToken() {
  return new Promise((resolve) => {
    const dialog = $('token-dialog');
    $('token-form').onsubmit = () => {
      state.token = $('token-input').value.trim();
      sessionStorage.setItem('covplan.token', state.token);
      resolve();
    };
    if (!dialog.open) dialog.showModal();
  });
}

// One JSON API call; a 401 asks for a token and tries again.
async function api(method, body = {}) {
  const headers = { 'Content-Type': 'application/json' };
  if (state.token) headers.Authorization = `Bearer ${state.token}`;
  const reply = await fetch(`/v1/${method}`, {
    method: 'POST', headers, body: JSON.stringify(body),
  });
  const json = await reply.json().catch(() => ({ status: reply.statusText, message: '' }));
  if (reply.status === 401) {
    await askToken();
    return api(method, body);
  }
  if (!reply.ok) throw new ApiError(json.status, json.message, reply.status);
  return json;
}

// ------------------------------------------------------------- map images

function base64Bytes(b64) {
  const text = atob(b64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
  return bytes;
}

// A binary PGM (P5, 8 or 16 bit) as a canvas.
function pgmCanvas(bytes) {
  let pos = 0;
  const fields = [];
  while (fields.length < 4) {
    while (pos < bytes.length && /\s/.test(String.fromCharCode(bytes[pos]))) ++pos;
    if (bytes[pos] === 35) {  // '#': a comment to the end of the line
      while (pos < bytes.length && bytes[pos] !== 10) ++pos;
      continue;
    }
    let token = '';
    while (pos < bytes.length && !/\s/.test(String.fromCharCode(bytes[pos]))) {
      token += String.fromCharCode(bytes[pos++]);
    }
    fields.push(token);
  }
  if (fields[0] !== 'P5') throw new Error('only binary PGM (P5) is drawn');
  const [w, h, max] = [Number(fields[1]), Number(fields[2]), Number(fields[3])];
  ++pos;  // the single whitespace after maxval
  const wide = max > 255;
  const canvas = document.createElement('canvas');
  canvas.width = w;
  canvas.height = h;
  const ctx = canvas.getContext('2d');
  const image = ctx.createImageData(w, h);
  for (let i = 0; i < w * h; ++i) {
    const raw = wide ? (bytes[pos + 2 * i] << 8) | bytes[pos + 2 * i + 1] : bytes[pos + i];
    const v = Math.round((255 * raw) / max);
    image.data.set([v, v, v, 255], 4 * i);
  }
  ctx.putImageData(image, 0, 0);
  return canvas;
}

async function pngCanvas(bytes) {
  const bitmap = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
  const canvas = document.createElement('canvas');
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  canvas.getContext('2d').drawImage(bitmap, 0, 0);
  return canvas;
}

// The raster map's picture as a canvas, or null for a polygon map.
async function mapCanvas(map) {
  if (!map || !map.raster) return null;
  const bytes = base64Bytes(map.raster.image);
  return bytes[0] === 0x89 ? pngCanvas(bytes) : pgmCanvas(bytes);
}

// ------------------------------------------------------------- map list

async function loadMaps() {
  const list = $('maps');
  list.replaceChildren();
  let token = '';
  do {
    const page = await api('ListMaps', { pageToken: token });
    for (const info of page.maps) list.append(mapItem(info));
    token = page.nextPageToken;
  } while (token);
  setStatus(`${list.children.length} maps`);
}

function mapItem(info) {
  const li = document.createElement('li');
  li.className = 'map-item';
  li.dataset.mapId = info.mapId;
  const thumb = document.createElement('canvas');
  thumb.width = 96;
  thumb.height = 64;
  const label = document.createElement('span');
  label.textContent = `${info.name || info.mapId.slice(0, 12)} · ${info.freeAreaM2.toFixed(0)} m²`;
  li.append(thumb, label);
  li.onclick = () => openMap(info.mapId).catch(showError);
  api('GetMap', { mapId: info.mapId, includeContent: true })
    .then((reply) => mapCanvas(reply.map))
    .then((canvas) => {
      if (!canvas) return;
      const s = Math.min(thumb.width / canvas.width, thumb.height / canvas.height);
      thumb.getContext('2d').drawImage(canvas, 0, 0, canvas.width * s, canvas.height * s);
    })
    .catch(() => {});
  return li;
}

async function upload() {
  const image = $('upload-image').files[0];
  const yaml = $('upload-yaml').files[0];
  const geojson = $('upload-geojson').files[0];
  const name = $('upload-name').value || (image || geojson || {}).name || 'map';
  let map;
  if (geojson) {
    map = { polygons: { polygons: geoJsonPolygons(JSON.parse(await geojson.text())) } };
  } else if (image) {
    const bytes = new Uint8Array(await image.arrayBuffer());
    let b64 = '';
    for (let i = 0; i < bytes.length; i += 0x8000) {
      b64 += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
    }
    map = { raster: { image: btoa(b64) } };
    if (yaml) map.raster.yaml = await yaml.text();
    else map.raster.resolution = Number($('upload-resolution').value);
  } else {
    throw new Error('choose an image or a GeoJSON file');
  }
  const reply = await api('PutMap', { name, map });
  await loadMaps();
  await openMap(reply.info.mapId);
}

// GeoJSON Polygon / MultiPolygon features in a local metric frame.
function geoJsonPolygons(doc) {
  const features = doc.type === 'FeatureCollection' ? doc.features : [doc];
  const ring = (coords) => ({ points: coords.map(([x, y]) => ({ x, y })) });
  const polygons = [];
  for (const f of features) {
    const g = f.geometry || f;
    const all = g.type === 'Polygon' ? [g.coordinates] : g.type === 'MultiPolygon' ? g.coordinates : [];
    for (const p of all) polygons.push({ outer: ring(p[0]), holes: p.slice(1).map(ring) });
  }
  return polygons;
}

// ------------------------------------------------------------- the view

function svgEl(name, attrs) {
  const el = document.createElementNS(SVG_NS, name);
  for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, v);
  return el;
}

function setBox(box) {
  state.box = box;
  $('view').setAttribute('viewBox', box.join(' '));
}

// The map point under a mouse event.
function mapPoint(event) {
  const svg = $('view');
  const p = new DOMPoint(event.clientX, event.clientY).matrixTransform(svg.getScreenCTM().inverse());
  return [p.x, -p.y];
}

function setUpPanZoom() {
  const svg = $('view');
  let drag = null;
  svg.addEventListener('wheel', (e) => {
    if (!state.box) return;
    e.preventDefault();
    const [x, y] = mapPoint(e);
    const f = Math.exp(e.deltaY * 0.0015);
    const [bx, by, bw, bh] = state.box;
    setBox([x + (bx - x) * f, -y + (by + y) * f, bw * f, bh * f]);
  }, { passive: false });
  svg.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY, box: state.box, moved: false };
  });
  svg.addEventListener('pointermove', (e) => {
    if (!drag || !state.box) return;
    const dx = e.clientX - drag.x;
    const dy = e.clientY - drag.y;
    if (Math.hypot(dx, dy) > 4) drag.moved = true;
    if (!drag.moved) return;
    const scale = drag.box[2] / svg.clientWidth;
    setBox([drag.box[0] - dx * scale, drag.box[1] - dy * scale, drag.box[2], drag.box[3]]);
  });
  svg.addEventListener('pointerup', (e) => {
    const wasClick = drag && !drag.moved;
    drag = null;
    if (wasClick && state.drawing) {
      state.drawing.points.push(mapPoint(e));
      drawZones();
    }
  });
}

async function openMap(mapId) {
  const reply = await api('GetMap', { mapId, includeContent: true });
  state.info = reply.info;
  state.zones = [];
  state.drawing = null;
  state.plan = null;
  for (const layer of ['grid', 'zones', 'transitions', 'ranks', 'sweeps', 'drawing']) {
    $(layer).replaceChildren();
  }
  $('figures').hidden = true;
  for (const li of $('maps').children) li.classList.toggle('open', li.dataset.mapId === mapId);
  const { resolution, originXM: ox, originYM: oy, widthPx, heightPx } = reply.info;
  const canvas = await mapCanvas(reply.map);
  const image = $('map-image');
  let [w, h] = [widthPx * resolution, heightPx * resolution];
  if (canvas) {
    image.setAttribute('href', canvas.toDataURL('image/png'));
    for (const [k, v] of Object.entries({ x: ox, y: -(oy + h), width: w, height: h })) {
      image.setAttribute(k, v);
    }
  } else {
    image.removeAttribute('href');
    [w, h] = drawPolygonMap(reply.map.polygons.polygons);
  }
  const margin = 0.05 * Math.max(w, h);
  setBox([ox - margin, -(oy + h) - margin, w + 2 * margin, h + 2 * margin]);
  $('plan-form').hidden = false;
  live.watch(mapId);
  $('hint').textContent = `${reply.info.name || mapId}: drag to pan, wheel to zoom.`;
  setStatus(`map ${mapId.slice(0, 12)} open`);
}

// A polygon map: its free space drawn in #grid's place; returns its size.
function drawPolygonMap(polygons) {
  let [minX, minY, maxX, maxY] = [Infinity, Infinity, -Infinity, -Infinity];
  let d = '';
  for (const p of polygons) {
    for (const r of [p.outer, ...(p.holes || [])]) {
      d += `M${r.points.map((q) => `${q.x},${q.y}`).join('L')}Z`;
      for (const q of r.points) {
        [minX, minY, maxX, maxY] = [Math.min(minX, q.x), Math.min(minY, q.y),
          Math.max(maxX, q.x), Math.max(maxY, q.y)];
      }
    }
  }
  $('grid').append(svgEl('path', { d, class: 'free-polygons', 'fill-rule': 'evenodd' }));
  return [maxX - minX, maxY - minY];
}

// ------------------------------------------------------------- zones

function drawZones() {
  const layer = $('zones');
  layer.replaceChildren();
  for (const z of state.zones) {
    layer.append(svgEl('polygon', {
      class: `zone ${z.kind}`, 'data-kind': z.kind, points: z.points.map((p) => p.join(',')).join(' '),
    }));
  }
  const drawing = $('drawing');
  drawing.replaceChildren();
  if (state.drawing && state.drawing.points.length) {
    drawing.append(svgEl('polyline', {
      class: `zone-draft ${state.drawing.kind}`,
      points: state.drawing.points.map((p) => p.join(',')).join(' '),
    }));
  }
  $('finish-zone').disabled = !state.drawing || state.drawing.points.length < 3;
}

function startZone(kind) {
  state.drawing = { kind, points: [] };
  drawZones();
  setStatus(`click the corners of the ${kind === 'nogo' ? 'no-go zone' : 'region'}, then Finish zone`);
}

function finishZone() {
  if (state.drawing && state.drawing.points.length >= 3) state.zones.push(state.drawing);
  state.drawing = null;
  drawZones();
  setStatus(`${state.zones.length} zones`);
}

const polygonOf = (z) => ({ outer: { points: [...z.points, z.points[0]].map(([x, y]) => ({ x, y })) } });

// ------------------------------------------------------------- plans

async function plan() {
  if (state.drawing) finishZone();
  const request = {
    mapId: state.info.mapId,
    planner: $('planner').value,
    robot: { toolWidthM: Number($('tool-width').value) },
    timeLimitS: Number($('time-limit').value),
    noGo: state.zones.filter((z) => z.kind === 'nogo').map(polygonOf),
    regions: state.zones.filter((z) => z.kind === 'region').map(polygonOf),
  };
  setStatus('planning...');
  const started = performance.now();
  state.plan = await api('Plan', request);
  const drawStart = performance.now();
  drawPlan(state.plan);
  const drawn = performance.now();
  $('view').dataset.planId = state.plan.planId;
  $('view').dataset.drawMs = (drawn - drawStart).toFixed(1);
  // The frame after the one that painted it (two animation frames on).
  requestAnimationFrame(() => requestAnimationFrame(() => {
    $('view').dataset.paintMs = (performance.now() - drawStart).toFixed(1);
  }));
  setStatus(`plan ${state.plan.planId.slice(0, 12)}: ${((drawn - started) / 1000).toFixed(2)} s`);
}

function drawPlan(p) {
  const g = p.grid;
  const centre = (c) => [g.originXM + (c.col + 0.5) * g.cellSizeM, g.originYM + (c.row + 0.5) * g.cellSizeM];
  const ranks = $('ranks');
  const sweeps = $('sweeps');
  const transitions = $('transitions');
  for (const layer of [ranks, sweeps, transitions]) layer.replaceChildren();
  const rankFragment = document.createDocumentFragment();
  p.ranks.forEach((r, i) => {
    const [a, b] = [centre(r.firstCell), centre(r.lastCell)];
    rankFragment.append(svgEl('line', {
      class: `rank ${r.orientation.toLowerCase()}`, 'data-rank': i,
      x1: a[0], y1: a[1], x2: b[0], y2: b[1],
    }));
  });
  ranks.append(rankFragment);
  // Planners without ranks (cells, STC): each coverage segment.
  if (!p.ranks.length) {
    const fragment = document.createDocumentFragment();
    for (let i = 1; i < p.path.length; ++i) {
      if (p.path[i].kind !== 'COVERAGE') continue;
      const [a, b] = [p.path[i - 1], p.path[i]];
      fragment.append(svgEl('line', { class: 'sweep', x1: a.x, y1: a.y, x2: b.x, y2: b.y }));
    }
    sweeps.append(fragment);
  }
  transitions.append(svgEl('polyline', {
    class: 'path', points: p.path.map((w) => `${w.x},${w.y}`).join(' '),
  }));
  for (let i = 1; i < p.path.length; ++i) {
    const kind = p.path[i].kind;
    if (kind !== 'TO_STATION' && kind !== 'FROM_STATION') continue;
    const [a, b] = [p.path[i - 1], p.path[i]];
    transitions.append(svgEl('line', { class: 'station', x1: a.x, y1: a.y, x2: b.x, y2: b.y }));
  }
  drawGrid(g);
  showFigures(p);
}

function drawGrid(g) {
  const layer = $('grid');
  layer.querySelectorAll('.cells').forEach((e) => e.remove());
  if (!$('show-grid').checked || !g || !g.freeCells.length) return;
  const s = g.cellSizeM;
  let d = '';
  g.freeCells.forEach((row, r) => {
    for (let c = 0; c < row.length; ++c) {
      if (row[c] === '1') d += `M${g.originXM + c * s},${g.originYM + r * s}h${s}v${s}h${-s}Z`;
    }
  });
  layer.append(svgEl('path', { class: 'cells', d }));
}

function showFigures(p) {
  const s = p.stats;
  const rows = [
    ['Plan', p.planId.slice(0, 12)],
    ['Planner', p.planner],
    ['Ranks', s.numRanks],
    ['Duration', `${s.estimatedDurationS.toFixed(0)} s`],
    ['Turning', `${s.turningTimeS.toFixed(0)} s`],
    ['Turns', s.numTurns],
    ['Coverage (grid)', `${(100 * s.coveredFreeAreaRatio).toFixed(1)} %`],
    ['Swept of reachable', s.reachableAreaM2 ? `${(100 * s.sweptReachableRatio).toFixed(1)} %` : '-'],
    ['Charge cycles', s.chargeCycles],
    ['Planning', `${s.planningMs.toFixed(0)} ms`],
    ['Termination', `${p.termination.reason} (${p.termination.limit})`],
  ];
  const list = $('figure-list');
  list.replaceChildren();
  for (const [k, v] of rows) {
    const dt = document.createElement('dt');
    dt.textContent = k;
    const dd = document.createElement('dd');
    dd.textContent = v;
    dd.dataset.figure = k;
    list.append(dt, dd);
  }
  $('figures').hidden = false;
}

function showError(e) {
  setStatus(e.message || String(e), true);
}

let live = null;

function main() {
  live = createLiveView({ api, svgEl, token: () => state.token, setStatus });
  setUpPanZoom();
  $('draw-nogo').onclick = () => startZone('nogo');
  $('draw-region').onclick = () => startZone('region');
  $('finish-zone').onclick = finishZone;
  $('clear-zones').onclick = () => { state.zones = []; state.drawing = null; drawZones(); };
  $('plan-button').onclick = () => plan().catch(showError);
  $('upload-button').onclick = () => upload().catch(showError);
  $('show-grid').onchange = () => state.plan && drawGrid(state.plan.grid);
  loadMaps().catch(showError);
}

main();
