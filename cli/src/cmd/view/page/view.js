// emray view: polls /status, draws the tiles of the render under way on the canvas,
// then the finished PNG; sends the options to /render; shows /explain's tree of the
// pixel clicked. `?autoclick=X,Y` explains pixel (X, Y) once the first image is done
// and `?layer=NAME` picks the first layer (for tests and links).
'use strict';
const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
let autoclick = params.get('autoclick');
let layer = params.get('layer') || 'colour';
// The token stays in the cookie the page's load set; the address bar loses it.
params.delete('token');
history.replaceState(null, '', location.pathname + (params.toString() ? '?' + params : ''));

const canvas = $('canvas');
const ctx = canvas.getContext('2d');
let gen = 0, since = 0, shown = 0, image = null, filled = false, heatmaps = false;

function fmt(ms) {
  if (ms === null || ms === undefined) return '–';
  return ms < 1000 ? ms.toFixed(0) + ' ms' : (ms / 1000).toFixed(2) + ' s';
}

function resize(w, h) {
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
}

function drawTile(t) {
  const raw = atob(t.rgb);
  const w = Math.min(t.w, canvas.width - t.x), h = Math.min(t.h, canvas.height - t.y);
  if (w <= 0 || h <= 0) return;
  const img = ctx.createImageData(w, h);
  for (let j = 0; j < h; j++) {
    for (let i = 0; i < w; i++) {
      const s = (j * t.w + i) * 3, d = (j * w + i) * 4;
      img.data[d] = raw.charCodeAt(s);
      img.data[d + 1] = raw.charCodeAt(s + 1);
      img.data[d + 2] = raw.charCodeAt(s + 2);
      img.data[d + 3] = 255;
    }
  }
  ctx.putImageData(img, t.x, t.y);
}

function showLayer() {
  const heat = $('heatmap');
  const has = image && image.layers.includes(layer);
  if (layer === 'colour' || !has) {
    heat.hidden = true;
    canvas.hidden = false;
  } else {
    heat.src = '/image.png?layer=' + layer + '&g=' + image.generation;
    heat.hidden = false;
    canvas.hidden = true;
  }
  for (const r of document.querySelectorAll('input[name=layer]')) r.checked = r.value === layer;
}

function update(st) {
  $('scene').textContent = st.scene;
  if (!filled) {
    filled = true;
    const form = $('options');
    for (const [k, v] of Object.entries(st.request.fields)) if (form.elements[k]) form.elements[k].value = v;
    heatmaps = st.request.heatmaps;
    if (layer !== 'colour' && !heatmaps) {
      heatmaps = true;
      render();
    }
  }
  const r = st.render;
  if (r.generation !== gen) {
    gen = r.generation;
    since = 0;
  }
  if (r.width) resize(r.width, r.height);
  for (const t of r.tiles) drawTile(t);
  since = r.next;
  $('phase').textContent = r.phase + (r.total ? ` ${r.done}/${r.total} tiles` : '');
  $('progress').value = r.total ? r.done / r.total : (r.phase === 'done' ? 1 : 0);
  const t = r.timings;
  $('timings').textContent = `load ${fmt(t.load)} · build ${fmt(t.build)} · render ${fmt(t.render)}`;
  const err = $('error');
  err.hidden = r.phase !== 'failed';
  if (r.error) err.textContent = r.error + (st.image ? '\n(showing the last image that rendered)' : '');
  if (st.image && st.image.generation !== shown) {
    shown = st.image.generation;
    image = st.image;
    const png = new Image();
    png.onload = () => {
      resize(png.width, png.height);
      ctx.drawImage(png, 0, 0);
      document.body.dataset.image = String(shown);
    };
    png.src = '/image.png?layer=colour&g=' + shown;
    const rep = st.image.report, form = $('options').elements;
    form['res'].placeholder = `${st.image.width}x${st.image.height}`;
    if (rep) {
      form['spp'].placeholder = rep.spp;
      form['max-depth'].placeholder = rep.max_depth;
      form['backend'].options[0].text = 'default (' + rep.backend + ')';
    }
    showLayer();
    if (autoclick) {
      const [x, y] = autoclick.split(',').map(Number);
      autoclick = null;
      explain(x, y);
    }
  }
}

function poll() {
  fetch(`/status?gen=${gen}&since=${since}`)
    .then((r) => r.json())
    .then(update)
    .catch(() => { $('phase').textContent = 'disconnected'; })
    .finally(() => setTimeout(poll, 250));
}

function render() {
  const q = new URLSearchParams(new FormData($('options')));
  q.delete('layer');
  q.set('heatmaps', heatmaps ? '1' : '0');
  fetch('/render?' + q).then((r) => r.json()).then((j) => {
    const err = $('error');
    err.hidden = !j.error;
    if (j.error) err.textContent = j.error;
  });
}

$('options').addEventListener('change', (e) => {
  if (e.target.name === 'layer') {
    layer = e.target.value;
    if (layer !== 'colour' && !(image && image.layers.includes(layer))) {
      heatmaps = true;
      render();
    }
    showLayer();
    return;
  }
  render();
});
$('options').addEventListener('submit', (e) => { e.preventDefault(); render(); });

function pixelOf(e) {
  const el = e.target;
  const sx = el.naturalWidth || el.width, sy = el.naturalHeight || el.height;
  const x = Math.floor(e.offsetX * sx / el.clientWidth), y = Math.floor(e.offsetY * sy / el.clientHeight);
  return [x, y];
}
for (const el of [canvas, $('heatmap')]) {
  el.addEventListener('click', (e) => {
    const [x, y] = pixelOf(e);
    if (image && x < image.width && y < image.height) explain(x, y);
  });
}

const num = (c) => (typeof c === 'number' ? +c.toPrecision(4) : String(c));
const v3 = (a) => (Array.isArray(a) ? a.map(num).join(' ') : num(a));
function swatch(c) {
  const s = document.createElement('span');
  s.className = 'swatch';
  if (!Array.isArray(c)) c = [c, c, c];
  const g = (v) => Math.round(255 * Math.min(1, Math.max(0, v)) ** (1 / 2.2));
  s.style.background = `rgb(${g(c[0])},${g(c[1])},${g(c[2])})`;
  return s;
}
function row(parent, text, colour) {
  const d = document.createElement('div');
  d.className = 'row';
  if (colour) d.append(swatch(colour), ' ');
  d.append(text);
  parent.append(d);
}

function rayNode(ray) {
  const d = document.createElement('details');
  d.className = 'ray ' + ray.kind;
  d.dataset.kind = ray.kind;
  d.open = ray.depth <= 2;
  const s = document.createElement('summary');
  const hit = ray.hit;
  const what = hit ? `hits ${hit.prim.kind} ${hit.prim.index}${hit.prim.source ? ' (' + hit.prim.source + ')' : ''}` : 'leaves the scene';
  s.append(`${ray.kind} ray, depth ${ray.depth}: ${what}; adds `, swatch(ray.contribution), ` ${v3(ray.contribution)}`);
  d.append(s);
  row(d, `from (${v3(ray.origin)}) along (${v3(ray.direction)}), weight ${v3(ray.weight)}`);
  if (hit) {
    const m = hit.material;
    row(d, `t = ${+hit.t.toPrecision(5)} at (${v3(hit.point)}), ${hit.entering ? 'front' : 'back'} side, normal (${v3(hit.normal)})`);
    row(d, `material ${m.index}${m.source ? ' (' + m.source + ')' : ''}: Ka ${m.ka} Kd ${m.kd} Ks ${m.ks} shine ${m.shine} Kr ${m.kr} T ${m.t} ior ${m.ior}`, m.color);
    for (const t of hit.terms) row(d, `${t.term} ${v3(t.value)}`, t.value);
    for (const a of hit.area_lights) row(d, `area light ${a.light}: ${a.visible}/${a.rays} rays see it, ${v3(a.value)}`, a.value);
    for (const l of hit.lights) {
      row(d, `light ${l.light}${l.source ? ' (' + l.source + ')' : ''}: ${l.status}, diffuse ${v3(l.diffuse)} + specular ${v3(l.specular)} = ${v3(l.value)}`, l.value);
    }
    row(d, `local light ${v3(hit.local)}`, hit.local);
    if (hit.boundary) row(d, `boundary n1 ${hit.boundary.n1} → n2 ${hit.boundary.n2}${hit.boundary.total_internal_reflection ? ', total internal reflection' : ''}`);
    for (const n of hit.not_cast) row(d, `${n.kind} ray not cast: ${n.why}`);
    for (const c of hit.children) d.append(rayNode(c));
  } else if (ray.background) {
    row(d, `background ${v3(ray.background)}`, ray.background);
  }
  row(d, `radiance ${v3(ray.radiance)}`, ray.radiance);
  return d;
}

function explain(x, y) {
  const panel = $('explain');
  panel.textContent = `explaining (${x}, ${y})…`;
  fetch(`/explain?x=${x}&y=${y}`).then((r) => r.json()).then((e) => {
    panel.textContent = '';
    if (e.error) {
      panel.append(e.error);
      return;
    }
    const h = document.createElement('div');
    h.append(`pixel (${e.x}, ${e.y}) of ${e.width}x${e.height}: `, swatch(e.value), ` ${v3(e.value)} (${e.backend})`);
    panel.append(h);
    for (const p of e.positions) for (const ray of p.samples) panel.append(rayNode(ray));
    panel.dataset.pixel = `${x},${y}`;
    mark(x, y);
  });
}

function mark(x, y) {
  const o = $('overlay');
  const el = canvas.hidden ? $('heatmap') : canvas;
  o.setAttribute('width', el.clientWidth);
  o.setAttribute('height', el.clientHeight);
  const k = el.clientWidth / (el.naturalWidth || el.width);
  o.innerHTML = `<circle cx="${(x + 0.5) * k}" cy="${(y + 0.5) * k}" r="6"/>`;
}

showLayer();
poll();
