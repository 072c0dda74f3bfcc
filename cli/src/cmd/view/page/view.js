// emray view: polls /status, draws the tiles of the render under way on the canvas,
// then the finished PNG; sends the options to /render; shows the tree of the pixel
// clicked and draws its rays over the image where they project (/rays); compares the
// backends (the `compare` box: Embree's render, the BVH's and their difference); shows
// an output variable (the `output variables` choice: a render that gathers them all).
// `?autoclick=X,Y` explains pixel (X, Y) once the first image is done, `?layer=NAME`
// picks the first layer and `?rays=0` leaves the rays undrawn (for tests and links).
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
let gen = 0, since = 0, shown = 0, image = null, filled = false, heatmaps = false, aovs = false;
// The clicked pixel's rays (/rays), and the tree path of the one to highlight.
let rays = null, highlight = null;
const HEATMAPS = ['rays', 'time', 'depth'], COMPARED = ['bvh', 'difference'];
// How each ray is drawn: its colour, and dashes for shadow rays.
const STYLE = {
  eye: ['#ffd23f', []], reflection: ['#4fc3f7', []], refraction: ['#e57cf2', []],
  light: ['#c8c8c8', [5, 4]], blocked: ['#ff6e5a', [5, 4]],
};

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
  for (const l of document.querySelectorAll('#layers .compared')) l.hidden = !(image && image.layers.includes('bvh'));
  $('options').elements['aov'].value = layer.startsWith('aov-') ? layer : '';
  showRange();
  drawRays();
}

// What the output variable shown spans: its layer maps that range linearly.
function showRange() {
  const el = $('aov-range'), name = layer.slice(4);
  const r = layer.startsWith('aov-') && image && image.aov ? image.aov[name] : null;
  el.hidden = !r;
  if (!r) return;
  const num = (v) => Number(v.toPrecision(4));
  const span = (a, b) => `${num(a)} to ${num(b)}`;
  if (name === 'position') {
    el.textContent = 'xyz'.split('').map((a, k) => `${a} ${span(r.min[k], r.max[k])}`).join(', ');
  } else if (name === 'depth') {
    el.textContent = `${span(r.min, r.max)} (near light, far dark)`;
  } else {
    el.textContent = `${span(r.min, r.max)} (black to white)`;
  }
}

// The layer `name` needs a render that makes it: the heat maps, the output variables,
// or the comparison.
function ask(name) {
  if (image && image.layers.includes(name)) return false;
  if (HEATMAPS.includes(name)) heatmaps = true;
  else if (name.startsWith('aov-')) aovs = true;
  else if (COMPARED.includes(name) && !$('options').elements['compare'].disabled) $('options').elements['compare'].checked = true;
  else return false;
  return true;
}

function update(st) {
  $('scene').textContent = st.scene;
  if (!filled) {
    filled = true;
    const form = $('options');
    for (const [k, v] of Object.entries(st.request.fields)) if (form.elements[k]) form.elements[k].value = v;
    heatmaps = st.request.heatmaps;
    aovs = st.request.aovs;
    const box = form.elements['compare'];
    box.checked = st.request.compare;
    if (!st.backends.includes('embree')) {
      box.disabled = true;
      box.checked = false;
      $('compare-control').title = 'This build has no Embree: only the BVH renders.';
      $('compare-control').append(' (no Embree in this build)');
    }
    if (layer !== 'colour' && ask(layer)) render();
  }
  const r = st.render;
  if (r.generation !== gen) {
    gen = r.generation;
    since = 0;
  }
  if (r.width) resize(r.width, r.height);
  for (const t of r.tiles) drawTile(t);
  since = r.next;
  const loaded = r.phase === 'loading' && r.loaded !== null ? ` ${r.loaded}%` : '';
  $('phase').textContent = r.phase + loaded + (r.pass ? ` on ${r.pass}` : '') + (r.total ? ` ${r.done}/${r.total} tiles` : '');
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
      drawRays();
    };
    png.src = '/image.png?layer=colour&g=' + shown;
    const rep = st.image.report, form = $('options').elements;
    form['res'].placeholder = `${st.image.width}x${st.image.height}`;
    if (rep) {
      form['spp'].placeholder = rep.spp;
      form['max-depth'].placeholder = rep.max_depth;
      form['backend'].options[0].text = 'default (' + rep.backend + ')';
    }
    showCompare(st.image.compare);
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

function showCompare(c) {
  const el = $('compare');
  el.hidden = !c;
  if (!c) return;
  el.classList.toggle('differ', c.differing > 0);
  el.textContent = `embree vs bvh: ${c.differing} of ${c.width}×${c.height} pixels differ` +
    (c.differing ? `, by at most ${c.max}/255 (difference layer ×${c.gain})` : '');
}

function render() {
  const q = new URLSearchParams(new FormData($('options')));
  q.delete('layer');
  q.delete('aov');
  q.set('heatmaps', heatmaps ? '1' : '0');
  q.set('aovs', aovs ? '1' : '0');
  q.set('compare', $('options').elements['compare'].checked ? '1' : '0');
  fetch('/render?' + q).then((r) => r.json()).then((j) => {
    const err = $('error');
    err.hidden = !j.error;
    if (j.error) err.textContent = j.error;
  });
}

$('options').addEventListener('change', (e) => {
  if (e.target.name === 'layer' || e.target.name === 'aov') {
    layer = e.target.value || 'colour';
    if (layer !== 'colour' && ask(layer)) render();
    showLayer();
    return;
  }
  if (e.target.name === 'compare' && !e.target.checked && COMPARED.includes(layer)) layer = 'colour';
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
  return d;
}

// Hovering `el` highlights the segment of tree path `path`.
function hover(el, path) {
  el.dataset.path = path;
  el.addEventListener('mouseover', (e) => {
    e.stopPropagation();
    if (highlight === path) return;
    highlight = path;
    for (const h of document.querySelectorAll('#explain .hover')) h.classList.remove('hover');
    (el.tagName === 'SUMMARY' ? el.parentElement : el).classList.add('hover');
    drawRays();
  });
}

function rayNode(ray, path) {
  const d = document.createElement('details');
  d.className = 'ray ' + ray.kind;
  d.dataset.kind = ray.kind;
  d.open = ray.depth <= 2;
  const s = document.createElement('summary');
  const hit = ray.hit;
  const what = hit ? `hits ${hit.prim.kind} ${hit.prim.index}${hit.prim.source ? ' (' + hit.prim.source + ')' : ''}` : 'leaves the scene';
  s.append(`${ray.kind} ray, depth ${ray.depth}: ${what}; adds `, swatch(ray.contribution), ` ${v3(ray.contribution)}`);
  d.append(s);
  hover(s, path);
  row(d, `from (${v3(ray.origin)}) along (${v3(ray.direction)}), weight ${v3(ray.weight)}`);
  if (hit) {
    const m = hit.material;
    row(d, `t = ${+hit.t.toPrecision(5)} at (${v3(hit.point)}), ${hit.entering ? 'front' : 'back'} side, normal (${v3(hit.normal)})`);
    row(d, `material ${m.index}${m.source ? ' (' + m.source + ')' : ''}: Ka ${m.ka} Kd ${m.kd} Ks ${m.ks} shine ${m.shine} Kr ${m.kr} T ${m.t} ior ${m.ior}`, m.color);
    for (const t of hit.terms) row(d, `${t.term} ${v3(t.value)}`, t.value);
    for (const a of hit.area_lights) row(d, `area light ${a.light}: ${a.visible}/${a.rays} rays see it, ${v3(a.value)}`, a.value);
    hit.lights.forEach((l, i) => {
      const r = row(d, `light ${l.light}${l.source ? ' (' + l.source + ')' : ''}: ${l.status}, diffuse ${v3(l.diffuse)} + specular ${v3(l.specular)} = ${v3(l.value)}`, l.value);
      if (l.shadow_ray) {
        r.classList.add('light');
        hover(r, `${path}.s${i}`);
      }
    });
    row(d, `local light ${v3(hit.local)}`, hit.local);
    if (hit.boundary) row(d, `boundary n1 ${hit.boundary.n1} → n2 ${hit.boundary.n2}${hit.boundary.total_internal_reflection ? ', total internal reflection' : ''}`);
    for (const n of hit.not_cast) row(d, `${n.kind} ray not cast: ${n.why}`);
    hit.children.forEach((c, i) => d.append(rayNode(c, `${path}.${i}`)));
  } else if (ray.background) {
    row(d, `background ${v3(ray.background)}`, ray.background);
  }
  row(d, `radiance ${v3(ray.radiance)}`, ray.radiance);
  return d;
}

function explain(x, y) {
  const panel = $('explain');
  panel.textContent = `explaining (${x}, ${y})…`;
  fetch(`/rays?x=${x}&y=${y}`).then((r) => r.json()).then((j) => {
    panel.textContent = '';
    if (j.error) {
      panel.append(j.error);
      return;
    }
    const e = j.tree;
    const h = document.createElement('div');
    h.append(`pixel (${e.x}, ${e.y}) of ${e.width}x${e.height}: `, swatch(e.value), ` ${v3(e.value)} (${e.backend})`);
    panel.append(h);
    e.positions.forEach((p, i) => p.samples.forEach((ray, j) => panel.append(rayNode(ray, `${i}.${j}`))));
    panel.dataset.pixel = `${x},${y}`;
    rays = { x, y, width: e.width, height: e.height, segments: j.segments };
    highlight = null;
    $('legend').hidden = false;
    drawRays();
    document.body.dataset.rays = String(j.segments.filter((s) => s.line).length);
  });
}

// The clicked pixel's rays on the overlay, over the layer shown: each one's part that
// shows in the image, a dot where it hits, the highlighted one last and wider.
function drawRays() {
  const o = $('overlay');
  const el = canvas.hidden ? $('heatmap') : canvas;
  const w = el.clientWidth, h = el.clientHeight, dpr = window.devicePixelRatio || 1;
  o.style.width = w + 'px';
  o.style.height = h + 'px';
  o.width = Math.max(1, Math.round(w * dpr));
  o.height = Math.max(1, Math.round(h * dpr));
  const c = o.getContext('2d');
  c.setTransform(dpr, 0, 0, dpr, 0, 0);
  c.clearRect(0, 0, w, h);
  if (!rays || !$('show-rays').checked || !w) return;
  const k = w / rays.width;
  const style = (s) => STYLE[s.kind === 'shadow' ? s.ends : s.kind] || STYLE.eye;
  const stroke = (s, width) => {
    const [[x0, y0], [x1, y1]] = s.line;
    const [colour, dash] = style(s);
    c.beginPath();
    c.moveTo(x0 * k, y0 * k);
    c.lineTo(x1 * k, y1 * k);
    c.setLineDash(dash);
    c.lineCap = 'round';
    if (s.kind !== 'shadow' || s.path === highlight) {
      c.strokeStyle = 'rgba(0,0,0,0.7)';
      c.lineWidth = width + 2;
      c.stroke();
    }
    c.strokeStyle = colour;
    c.lineWidth = width;
    c.stroke();
    if (s.ends === 'hit' && s.end && s.end[0] >= 0 && s.end[1] >= 0 && s.end[0] <= rays.width && s.end[1] <= rays.height) {
      c.setLineDash([]);
      c.beginPath();
      c.arc(s.end[0] * k, s.end[1] * k, width + 1.5, 0, 2 * Math.PI);
      c.fillStyle = colour;
      c.fill();
      c.strokeStyle = 'rgba(0,0,0,0.7)';
      c.lineWidth = 1;
      c.stroke();
    }
  };
  const kinds = new Set([...document.querySelectorAll('input[name=kind]:checked')].map((b) => b.value));
  const lit = rays.segments.filter((s) => s.line && s.path !== highlight && kinds.has(s.kind));
  // Shadow rays under the others, deeper rays under shallower ones.
  lit.sort((a, b) => (b.kind === 'shadow') - (a.kind === 'shadow') || b.depth - a.depth);
  for (const s of lit) stroke(s, s.kind === 'shadow' ? 1.25 : 1.5);
  const hl = rays.segments.find((s) => s.line && s.path === highlight);
  if (hl) stroke(hl, 3.5);
  c.setLineDash([]);
  c.beginPath();
  c.arc((rays.x + 0.5) * k, (rays.y + 0.5) * k, 6, 0, 2 * Math.PI);
  c.strokeStyle = '#fff';
  c.lineWidth = 1.5;
  c.stroke();
}
$('legend').addEventListener('change', drawRays);
if (params.get('rays') === '0') $('show-rays').checked = false;
$('explain').addEventListener('mouseleave', () => {
  highlight = null;
  for (const h of document.querySelectorAll('#explain .hover')) h.classList.remove('hover');
  drawRays();
});
window.addEventListener('resize', drawRays);
$('heatmap').addEventListener('load', drawRays);

showLayer();
poll();
