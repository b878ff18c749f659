'use strict';
// The comparison page's viewer. It reads window.PENUMBRA (page_data.js, written beside the
// page): galleries of measured images and the results folder's tables. The pair on screen is A
// against B: B opens as A's reference (its gallery's ground truth, exact image or brute force, or
// the same frame under the other shading) and follows A from gallery to gallery; both sides are
// drawn with B's tone mapping and one exposure; the pair's numbers are computed here from the
// stored values. Opened with #selftest, selftest.js (inlined after this) checks the page.
const PAGE = (function () {
  const errors = [];
  window.addEventListener('error', (e) => errors.push(String(e.message || e)));
  window.addEventListener('unhandledrejection', (e) => errors.push('unhandled rejection: ' + String(e.reason)));
  const consoleError = console.error.bind(console);
  console.error = (...args) => {
    errors.push(args.map(String).join(' '));
    consoleError(...args);
  };

  const DATA = window.PENUMBRA;
  if (!DATA) errors.push('page_data.js did not load');
  const SELFTEST = location.hash === '#selftest';
  const NO_RECEIVER = -1;
  const NO_RECEIVER_RGB = [20, 24, 60];
  const ZOOM_MAX = 64;
  const $ = (id) => document.getElementById(id);
  // A link to a file of the results folder by its relative path: each part percent-encoded and
  // the whole led by ./, so that no file name (`javascript:x.csv`, `a#b.csv`) reads as a scheme
  // or a fragment.
  const fileUrl = (path) => './' + path.split('/').map(encodeURIComponent).join('/');

  // ---- decoding ----------------------------------------------------------------------------
  async function inflate(b64) {
    const bin = atob(b64);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // IEEE 754 half to number.
  function halfToFloat(h) {
    const sign = h & 0x8000 ? -1 : 1;
    const exponent = (h >> 10) & 0x1f;
    const fraction = h & 0x3ff;
    if (exponent === 0) return sign * fraction * Math.pow(2, -24);
    if (exponent === 31) return fraction ? NaN : sign * Infinity;
    return sign * (1 + fraction / 1024) * Math.pow(2, exponent - 15);
  }

  // Every half float's value, by its bits.
  let halves = null;
  function halfTable() {
    if (!halves) {
      halves = new Float32Array(65536);
      for (let h = 0; h < 65536; h++) halves[h] = halfToFloat(h);
    }
    return halves;
  }

  // Byte planes of wrapping deltas of bit patterns (data.rs) back to values.
  function unplane(bytes, n, bits, name) {
    const width = bits / 8;
    if (bytes.length !== width * n) throw new Error(`${name}: ${bytes.length} bytes for ${n} pixels of ${bits} bits`);
    const values = new Float32Array(n);
    if (bits === 16) {
      const table = halfTable();
      let previous = 0;
      for (let i = 0; i < n; i++) {
        previous = (previous + (bytes[i] | (bytes[n + i] << 8))) & 0xffff;
        values[i] = table[previous];
      }
      return values;
    }
    // Int32 sums wrap as the u32 deltas do; the Uint32Array stores them as those bits.
    const asBits = new Uint32Array(values.buffer);
    let previous = 0;
    for (let i = 0; i < n; i++) {
      previous = (previous + (bytes[i] | (bytes[n + i] << 8) | (bytes[2 * n + i] << 16) | (bytes[3 * n + i] << 24))) | 0;
      asBits[i] = previous;
    }
    return values;
  }

  // Galleries as {title, first, count, tone, bits, reference, against} and every shot as
  // {label, exr, png, key, gallery, index, width, height, values: Float32Array, flip, flipMean}.
  async function decode(data) {
    const galleries = [];
    const shots = [];
    for (const [g, gallery] of data.galleries.entries()) {
      const first = shots.length;
      const n = gallery.width * gallery.height;
      for (const [k, s] of gallery.shots.entries()) {
        const values = s.same !== null ? shots[first + s.same].values : unplane(await inflate(s.data), n, gallery.bits, s.exr);
        let flip = null;
        if (s.flip !== null) {
          const bytes = await inflate(s.flip);
          if (bytes.length !== n) throw new Error(`${s.exr}: FLIP map of ${bytes.length} pixels for ${n}`);
          flip = new Float32Array(n);
          for (let i = 0; i < n; i++) flip[i] = bytes[i] / 255;
        }
        shots.push({
          label: s.label, exr: s.exr, png: s.png, key: s.key, gallery: g, index: k,
          width: gallery.width, height: gallery.height, values, flip, flipMean: s.flip_mean,
        });
      }
      galleries.push({
        title: gallery.title, first, count: gallery.shots.length, tone: gallery.tone, bits: gallery.bits,
        reference: gallery.reference === null ? null : first + gallery.reference, against: gallery.against,
      });
    }
    return { galleries, shots };
  }

  // ---- colour ------------------------------------------------------------------------------
  const toByte = (x) => Math.round(Math.min(Math.max(x, 0), 1) * 255);

  // The same mapping as the PNGs (output/images.rs), scaled by 2^ev.
  function toneByte(tone, v, gain) {
    if (tone.kind === 'linear') return toByte(v * gain);
    const x = (2 * v * gain) / tone.p99;
    return toByte(Math.pow(x / (1 + x), 1 / 2.2));
  }

  // Magma, as FLIP shows its maps: nine stops, linearly interpolated.
  const MAGMA = [[0, 0, 4], [28, 16, 68], [79, 18, 123], [129, 37, 129], [181, 54, 122], [229, 80, 100], [251, 135, 97], [254, 194, 135], [252, 253, 191]];
  function magma(t) {
    const x = Math.min(Math.max(t, 0), 1) * (MAGMA.length - 1);
    const i = Math.min(Math.floor(x), MAGMA.length - 2);
    const f = x - i;
    return MAGMA[i].map((c, k) => Math.round(c + f * (MAGMA[i + 1][k] - c)));
  }
  // Blue (negative) - white - red (positive), as output/images.rs draws signed errors.
  function diverging(t) {
    const c = Math.min(Math.max(t, -1), 1);
    return c >= 0 ? [255, toByte(1 - c), toByte(1 - c)] : [toByte(1 + c), toByte(1 + c), 255];
  }

  // ---- error views and their scales --------------------------------------------------------
  const VIEWS = {
    diff: { name: 'A − B', value: (a, b) => a - b, colour: (t) => diverging(t), signed: true },
    relse: { name: '(A − B)² / (B² + 0.01)', value: (a, b) => ((a - b) * (a - b)) / (b * b + 0.01), colour: (t) => magma(t), signed: false },
    flip: { name: 'FLIP', value: null, colour: (t) => magma(t), signed: false },
  };
  // A log scale spans four decades below its maximum.
  const LOG_DECADES = 4;

  // Per pixel the error view's value (NaN where a pixel has no receiver or there is no map).
  function errorValues(view, a, b) {
    const n = a.values.length;
    const out = new Float64Array(n).fill(NaN);
    if (view === 'flip') {
      if (a.flip) out.set(a.flip);
      return out;
    }
    const f = VIEWS[view].value;
    for (let i = 0; i < n; i++) {
      const x = a.values[i];
      const y = b.values[i];
      if (x !== NO_RECEIVER && y !== NO_RECEIVER) out[i] = f(x, y);
    }
    return out;
  }

  // The 99th percentile of |value| (1 where that is 0).
  function percentile99(values) {
    const m = Array.from(values, Math.abs).filter(Number.isFinite).sort((x, y) => x - y);
    const s = m.length ? m[Math.min(m.length - 1, Math.floor(0.99 * m.length))] : 0;
    return s > 0 ? s : 1;
  }

  // The error view's maximum under the chosen scale: auto (99th percentile), fixed (the values'
  // own range: 1, or the exposure for radiance; FLIP 1), the user's maximum, or log (four decades
  // below the largest |value|).
  function errorMaximum(values) {
    if (state.view === 'flip') return 1;
    if (state.scale === 'fixed') return state.view === 'diff' && tone().kind === 'radiance' ? tone().p99 : 1;
    if (state.scale === 'user') return state.userMax > 0 ? state.userMax : 1;
    if (state.scale === 'log') {
      const m = Array.from(values, Math.abs).filter(Number.isFinite).reduce((x, y) => Math.max(x, y), 0);
      return m > 0 ? m : 1;
    }
    return percentile99(values);
  }

  // Where `v` falls on the colour scale: -1..1 (signed views) or 0..1.
  function position(v, max) {
    if (state.scale !== 'log') return v / max;
    const lo = max * Math.pow(10, -LOG_DECADES);
    const t = Math.abs(v) <= lo ? 0 : Math.min(Math.log10(Math.abs(v) / lo) / LOG_DECADES, 1);
    return Math.sign(v) * t;
  }

  // ---- the viewer's state ------------------------------------------------------------------
  const state = {
    a: 0, b: 0, mode: 'split', split: 0.5, showB: false, ev: 0, view: 'diff', scale: 'auto', userMax: 1,
    zoom: 1, panX: 0, panY: 0,
  };
  let galleries = [];
  let shots = [];
  const layers = new Map();
  // The tone both sides are drawn with: B's (the pinned reference's).
  const tone = () => galleries[shots[state.b].gallery].tone;
  const sameSize = (i, j) => shots[i].width === shots[j].width && shots[i].height === shots[j].height;

  // The image B follows A to: A's gallery's reference; else the same image of the gallery A's
  // is set against (the other shading); else B as it is, where it is of A's size and not A; else
  // the next image of A's gallery.
  function partner(i, current) {
    const s = shots[i];
    const g = galleries[s.gallery];
    if (g.reference !== null && g.reference !== i) return g.reference;
    if (g.against !== null && s.index < galleries[g.against].count && sameSize(galleries[g.against].first + s.index, i)) {
      return galleries[g.against].first + s.index;
    }
    if (current !== undefined && current !== i && sameSize(current, i)) return current;
    return g.count > 1 ? g.first + ((s.index + 1) % g.count) : i;
  }

  // The image the page opens on: the first gallery's first image that is not its reference.
  function opening() {
    const g = galleries[0];
    for (let k = 0; k < g.count; k++) if (g.first + k !== g.reference) return g.first + k;
    return g.first;
  }

  // Drawn pictures, the most recently used kept (each exposure step draws both sides anew).
  const LAYERS_KEPT = 48;
  function layer(shot, key, paint) {
    const id = `${shots.indexOf(shot)}:${key}`;
    if (layers.has(id)) {
      const c = layers.get(id);
      layers.delete(id);
      layers.set(id, c);
    } else {
      while (layers.size >= LAYERS_KEPT) layers.delete(layers.keys().next().value);
      const c = document.createElement('canvas');
      c.width = shot.width;
      c.height = shot.height;
      const ctx = c.getContext('2d');
      const img = ctx.createImageData(shot.width, shot.height);
      paint(img.data);
      ctx.putImageData(img, 0, 0);
      layers.set(id, c);
    }
    return layers.get(id);
  }

  // A shot drawn with the pair's tone at the pair's exposure.
  function picture(shot) {
    const gain = Math.pow(2, state.ev);
    const t = tone();
    return layer(shot, `${JSON.stringify(t)}:${state.ev}`, (px) => {
      const linear = t.kind === 'linear';
      for (let i = 0; i < shot.values.length; i++) {
        const v = shot.values[i];
        const at = 4 * i;
        if (v === NO_RECEIVER && linear) {
          px.set(NO_RECEIVER_RGB, at);
        } else {
          px.fill(toneByte(t, v, gain), at, at + 3);
        }
        px[at + 3] = 255;
      }
    });
  }

  // Whether A's FLIP map is A against B (FLIP is measured against the gallery's reference).
  const flipShown = () => shots[state.a].flip !== null && galleries[shots[state.a].gallery].reference === state.b;

  // ---- the pair's numbers ------------------------------------------------------------------
  // Over the pixels where both have a receiver: MSE, relative MSE (÷ (B² + 0.01), as the error
  // view), max |A − B|; pixels differing counts every pixel whose bits differ; mean FLIP is A's
  // map's (exact, from the file) where B is the map's reference.
  const numbersCache = new Map();
  function pairNumbers(i, j) {
    const key = `${i}/${j}`;
    if (!numbersCache.has(key)) {
      const [a, b] = [shots[i], shots[j]];
      const [bitsA, bitsB] = [new Uint32Array(a.values.buffer), new Uint32Array(b.values.buffer)];
      let [compared, differing, se, rel, max] = [0, 0, 0, 0, 0];
      for (let k = 0; k < a.values.length; k++) {
        if (bitsA[k] !== bitsB[k]) differing++;
        const [x, y] = [a.values[k], b.values[k]];
        if (x === NO_RECEIVER || y === NO_RECEIVER) continue;
        const d = x - y;
        compared++;
        se += d * d;
        rel += (d * d) / (y * y + 0.01);
        max = Math.max(max, Math.abs(d));
      }
      numbersCache.set(key, {
        pixels: a.values.length, compared, differing, identical: differing === 0,
        mse: compared ? se / compared : NaN, relmse: compared ? rel / compared : NaN, max: compared ? max : NaN,
        flip: galleries[a.gallery].reference === j && a.flipMean !== null ? a.flipMean : NaN,
      });
    }
    return numbersCache.get(key);
  }

  const fmt = (v) => (Number.isFinite(v) ? (v === 0 ? '0' : v.toPrecision(6)) : '—');

  function showNumbers() {
    const n = pairNumbers(state.a, state.b);
    $('num-mse').textContent = fmt(n.mse);
    $('num-relmse').textContent = fmt(n.relmse);
    $('num-flip').textContent = fmt(n.flip);
    $('num-flip').title = Number.isFinite(n.flip) ? 'mean of A\'s FLIP map against its gallery\'s reference (B)' : 'FLIP is measured against A\'s gallery\'s reference only';
    $('num-max').textContent = fmt(n.max);
    $('num-differ').textContent = String(n.differing);
    $('num-pixels').textContent = String(n.pixels);
    $('num-compared').textContent = String(n.compared);
  }

  // ---- drawing -----------------------------------------------------------------------------
  let errorCache = null;
  function errorLayer() {
    const a = shots[state.a];
    const key = `${state.a}/${state.b}/${state.view}/${state.scale}/${state.userMax}/${JSON.stringify(tone())}`;
    if (!errorCache || errorCache.key !== key) {
      const values = errorValues(state.view, a, shots[state.b]);
      const max = errorMaximum(values);
      const c = document.createElement('canvas');
      c.width = a.width;
      c.height = a.height;
      const ctx = c.getContext('2d');
      const img = ctx.createImageData(a.width, a.height);
      const view = VIEWS[state.view];
      for (let i = 0; i < values.length; i++) {
        img.data.set(Number.isFinite(values[i]) ? view.colour(position(values[i], max)) : [96, 96, 96], 4 * i);
        img.data[4 * i + 3] = 255;
      }
      ctx.putImageData(img, 0, 0);
      errorCache = { key, values, max, canvas: c };
    }
    return errorCache;
  }

  function draw(canvas, paint) {
    const ctx = canvas.getContext('2d');
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = '#2b2b2b';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    ctx.imageSmoothingEnabled = false;
    ctx.setTransform(state.zoom, 0, 0, state.zoom, state.panX, state.panY);
    paint(ctx);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
  }

  // A corner label ("A", "B") drawn on the image.
  function tag(ctx, text, x, right) {
    ctx.font = 'bold 15px system-ui, sans-serif';
    const w = ctx.measureText(text).width + 12;
    ctx.fillStyle = 'rgba(0, 0, 0, 0.65)';
    ctx.fillRect(right ? x - w : x, 6, w, 22);
    ctx.fillStyle = '#ffd400';
    ctx.fillText(text, (right ? x - w : x) + 6, 22);
  }

  function render() {
    if (!shots.length) return;
    const a = shots[state.a];
    const b = shots[state.b];
    const compare = $('view-compare');
    const divider = Math.round(state.split * compare.width);
    draw(compare, (ctx) => {
      if (state.mode === 'toggle') {
        ctx.drawImage(picture(state.showB ? b : a), 0, 0);
        return;
      }
      const x = (divider - state.panX) / state.zoom;
      for (const [shot, left] of [[a, true], [b, false]]) {
        ctx.save();
        ctx.beginPath();
        if (left) ctx.rect(-1e6, -1e6, x + 1e6, 2e6);
        else ctx.rect(x, -1e6, 2e6, 2e6);
        ctx.clip();
        ctx.drawImage(picture(shot), 0, 0);
        ctx.restore();
      }
    });
    const ctx = compare.getContext('2d');
    if (state.mode === 'split') {
      ctx.fillStyle = '#ffd400';
      ctx.fillRect(divider - 1, 0, 2, compare.height);
      tag(ctx, 'A', 6, false);
      tag(ctx, 'B', compare.width - 6, true);
    } else {
      tag(ctx, state.showB ? 'B' : 'A', 6, false);
    }
    $('compare-caption').textContent = state.mode === 'toggle'
      ? `showing ${state.showB ? 'B' : 'A'}: ${(state.showB ? b : a).label}`
      : `A (left): ${a.label} · B (right): ${b.label}`;
    $('compare-caption').title = `A: ${galleries[a.gallery].title} / ${a.label}\nB: ${galleries[b.gallery].title} / ${b.label}`;
    $('tone-caption').textContent = tone().kind === 'linear'
      ? 'both sides: values 0…1 as grey'
      : `both sides: B's exposure (p99 ${tone().p99.toPrecision(4)})`;
    showNumbers();
    const identical = pairNumbers(state.a, state.b).identical;
    const view = VIEWS[state.view];
    if (identical) {
      const c = $('view-error');
      const e = c.getContext('2d');
      e.setTransform(1, 0, 0, 1, 0, 0);
      e.fillStyle = '#2b2b2b';
      e.fillRect(0, 0, c.width, c.height);
      e.fillStyle = '#f0f0f0';
      e.font = '20px system-ui, sans-serif';
      e.textAlign = 'center';
      e.fillText('A and B are bit-identical:', c.width / 2, c.height / 2 - 14);
      e.fillText(`every one of ${a.values.length} values equal`, c.width / 2, c.height / 2 + 16);
      e.textAlign = 'start';
      $('error-caption').textContent = 'A and B are bit-identical: no error to show';
    } else {
      const e = errorLayer();
      draw($('view-error'), (ctx) => ctx.drawImage(e.canvas, 0, 0));
      $('error-caption').textContent = state.view === 'flip'
        ? `FLIP of A against B (its gallery's reference)`
        : `${view.name}, ${SCALES[state.scale]}`;
      colourBar(e.max);
    }
    $('colour-scale').style.visibility = identical ? 'hidden' : 'visible';
    $('files').innerHTML = '';
    for (const [name, s] of [['A', a], ['B', b]]) {
      $('files').append(`${name}: `);
      for (const f of [s.exr, s.png]) {
        const link = document.createElement('a');
        link.href = fileUrl(f);
        link.textContent = f;
        $('files').append(link, ' ');
      }
    }
    remember();
  }
  const SCALES = { auto: 'scale: 99th percentile of |value|', fixed: 'scale: the values\' range', user: 'scale: your maximum', log: `log scale, ${LOG_DECADES} decades` };

  function colourBar(max) {
    const bar = $('colour-bar');
    const ctx = bar.getContext('2d');
    const view = VIEWS[state.view];
    const lo = view.signed ? -1 : 0;
    for (let x = 0; x < bar.width; x++) {
      ctx.fillStyle = `rgb(${view.colour(lo + ((1 - lo) * (x + 0.5)) / bar.width).join(',')})`;
      ctx.fillRect(x, 0, 1, bar.height);
    }
    const floor = max * Math.pow(10, -LOG_DECADES);
    $('bar-lo').textContent = state.scale === 'log' ? (view.signed ? `−${max.toPrecision(3)}` : floor.toPrecision(3)) : (view.signed ? -max : 0).toPrecision(3);
    $('bar-hi').textContent = max.toPrecision(3);
  }

  // The zoom at which A fills the canvas.
  function fitZoom() {
    const a = shots[state.a];
    const c = $('view-compare');
    return Math.min(c.width / a.width, c.height / a.height);
  }

  // Fits the image in the canvas at any (fractional) zoom, centred.
  function fit() {
    const a = shots[state.a];
    const c = $('view-compare');
    state.zoom = fitZoom();
    state.panX = (c.width - a.width * state.zoom) / 2;
    state.panY = (c.height - a.height * state.zoom) / 2;
  }

  // The zoom's bounds: half the fit, and 64x (twice the fit, for an image that small).
  const zoomBounds = () => [fitZoom() / 2, Math.max(ZOOM_MAX, 2 * fitZoom())];

  // Zoom by `factor` about canvas point (cx, cy), within the bounds.
  function zoomAt(cx, cy, factor) {
    const [least, most] = zoomBounds();
    const zoom = Math.min(Math.max(state.zoom * factor, least), most);
    const f = zoom / state.zoom;
    state.panX = cx - (cx - state.panX) * f;
    state.panY = cy - (cy - state.panY) * f;
    state.zoom = zoom;
  }

  // ---- the view in the URL -----------------------------------------------------------------
  function serialise() {
    const p = new URLSearchParams();
    p.set('a', shots[state.a].exr);
    p.set('b', shots[state.b].exr);
    for (const k of ['mode', 'split', 'ev', 'view', 'scale', 'userMax', 'zoom', 'panX', 'panY']) p.set(k, String(state[k]));
    return p.toString();
  }

  // Applies a serialised view; false where it names no image of this page.
  function restore(text) {
    const p = new URLSearchParams(text);
    const find = (exr) => shots.findIndex((s) => s.exr === exr);
    const [a, b] = [find(p.get('a')), find(p.get('b'))];
    if (a < 0) return false;
    choose(a, b >= 0 ? b : undefined);
    // What the link leaves out is as the page opens: fitted, slider at the middle, 0 EV.
    fit();
    Object.assign(state, { split: 0.5, ev: 0, userMax: 1 });
    const number = (k, lo, hi) => {
      const v = p.has(k) ? Number(p.get(k)) : NaN;
      return Number.isFinite(v) ? Math.min(Math.max(v, lo), hi) : state[k];
    };
    const own = (o, k) => k !== null && Object.prototype.hasOwnProperty.call(o, k);
    state.mode = p.get('mode') === 'toggle' ? 'toggle' : 'split';
    state.view = own(VIEWS, p.get('view')) ? p.get('view') : 'diff';
    state.scale = own(SCALES, p.get('scale')) ? p.get('scale') : 'auto';
    const [least, most] = zoomBounds();
    state.split = number('split', 0, 1);
    state.ev = number('ev', -6, 6);
    if (Number(p.get('userMax')) > 0) state.userMax = Math.min(Number(p.get('userMax')), Number.MAX_VALUE);
    state.zoom = number('zoom', least, most);
    state.panX = number('panX', -1e7, 1e7);
    state.panY = number('panY', -1e7, 1e7);
    syncControls();
    render();
    return true;
  }

  // The view into the URL, a moment after the last change: browsers refuse (Safari and Firefox
  // throw) more than about a hundred history updates in a few seconds, which a slider's drag
  // makes.
  let rememberLater = null;
  function remember() {
    if (SELFTEST) return;
    clearTimeout(rememberLater);
    rememberLater = setTimeout(() => {
      try {
        history.replaceState(null, '', '#' + serialise());
      } catch (e) {
        // Throttled: the next change writes it.
      }
    }, 250);
  }

  // ---- pixel readout -----------------------------------------------------------------------
  // A pixel's value; an error view's value (NaN where either pixel has no receiver: an error of
  // exactly -1, black against white, is a value), FLIP to the three decimals its map keeps.
  const show = (v) => (v === NO_RECEIVER ? 'no receiver' : Number.isFinite(v) ? v.toPrecision(7) : '—');
  const showError = (v) => (!Number.isFinite(v) ? '—' : state.view === 'flip' ? v.toFixed(3) : v.toPrecision(7));

  function canvasPoint(canvas, clientX, clientY) {
    const r = canvas.getBoundingClientRect();
    return [((clientX - r.left) * canvas.width) / r.width, ((clientY - r.top) * canvas.height) / r.height];
  }

  function pixelAt(canvas, clientX, clientY) {
    const [cx, cy] = canvasPoint(canvas, clientX, clientY);
    return [Math.floor((cx - state.panX) / state.zoom), Math.floor((cy - state.panY) / state.zoom)];
  }

  function readout(x, y) {
    const a = shots[state.a];
    const b = shots[state.b];
    const out = $('readout');
    if (x < 0 || y < 0 || x >= a.width || y >= a.height) {
      out.textContent = 'outside the image';
      return;
    }
    const i = y * a.width + x;
    const e = errorLayer().values[i];
    out.innerHTML = '';
    const part = (label, id, text) => {
      const s = document.createElement('span');
      s.id = id;
      s.textContent = text;
      out.append(label, s, '  ');
    };
    part('pixel ', 'read-x', String(x));
    part(', ', 'read-y', String(y));
    part('A ', 'read-a', show(a.values[i]));
    part('B ', 'read-b', show(b.values[i]));
    part(`${VIEWS[state.view].name} `, 'read-e', showError(e));
  }

  // ---- controls ----------------------------------------------------------------------------
  function fillPicks() {
    const options = (select, keep) => {
      select.innerHTML = '';
      let group = null;
      shots.forEach((s, i) => {
        if (!keep(s, i)) return;
        if (!group || group.label !== galleries[s.gallery].title) {
          group = document.createElement('optgroup');
          group.label = galleries[s.gallery].title;
          select.append(group);
        }
        const o = new Option(`${s.index + 1}. ${s.label}`, String(i));
        if (i === galleries[s.gallery].reference) o.text += ' (reference)';
        group.append(o);
      });
    };
    options($('pick-a'), () => true);
    options($('pick-b'), (s, i) => sameSize(i, state.a));
    $('pick-a').value = String(state.a);
    $('pick-b').value = String(state.b);
  }

  // The controls showing the state (after a view is restored or a default changes).
  function syncControls() {
    const flip = $('error-view').querySelector('option[value="flip"]');
    flip.disabled = !flipShown();
    if (state.view === 'flip' && flip.disabled) state.view = 'diff';
    $('mode').value = state.mode;
    $('split').value = String(state.split);
    $('split-label').style.visibility = state.mode === 'split' ? 'visible' : 'hidden';
    $('exposure').value = String(state.ev);
    $('exposure-value').textContent = `${state.ev} EV`;
    $('error-view').value = state.view;
    $('scale').value = state.scale;
    $('user-max').value = String(state.userMax);
    $('user-max').disabled = state.scale !== 'user';
  }

  // A against b (default: A's partner, B kept where it still is one).
  function choose(a, b) {
    const newSize = !sameSize(a, state.a);
    state.a = a;
    state.b = b !== undefined && sameSize(b, a) ? b : partner(a, newSize ? undefined : state.b);
    if (newSize) fit();
    fillPicks();
    syncControls();
    render();
  }

  function toggle() {
    if (state.mode !== 'toggle') {
      state.mode = 'toggle';
      state.showB = true;
    } else {
      state.showB = !state.showB;
    }
    syncControls();
    render();
  }

  // Keys act unless the user is typing (a text or number field); a select or slider that kept
  // the focus does not swallow them.
  function onKey(e) {
    const t = e.target;
    if (t.tagName === 'INPUT' && (t.type === 'text' || t.type === 'number')) return;
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.key === 't' || e.key === 'T') {
      toggle();
      e.preventDefault();
    } else if (/^[0-9]$/.test(e.key) && shots.length) {
      // Number keys: A jumps through its gallery (1 the first, 0 the tenth) against the pinned B.
      const g = galleries[shots[state.a].gallery];
      const k = (Number(e.key) + 9) % 10;
      if (k < g.count) choose(g.first + k, state.b);
      e.preventDefault();
    }
  }

  function wire() {
    const changed = (id, apply) => $(id).addEventListener('change', (e) => {
      apply(e.target.value);
      // A select keeps no focus, so that keys reach the page.
      if (e.target.tagName === 'SELECT') e.target.blur();
      syncControls();
      render();
    });
    $('pick-a').addEventListener('change', (e) => {
      choose(Number(e.target.value));
      e.target.blur();
    });
    $('pick-b').addEventListener('change', (e) => {
      choose(state.a, Number(e.target.value));
      e.target.blur();
    });
    changed('mode', (v) => {
      state.mode = v;
    });
    changed('error-view', (v) => {
      state.view = v;
    });
    changed('scale', (v) => {
      if (v === 'user' && state.scale !== 'user' && !pairNumbers(state.a, state.b).identical) state.userMax = Number(errorLayer().max.toPrecision(3));
      state.scale = v;
    });
    changed('user-max', (v) => {
      if (Number(v) > 0) state.userMax = Number(v);
    });
    $('split').addEventListener('input', (e) => {
      state.split = Number(e.target.value);
      render();
    });
    $('toggle').addEventListener('click', toggle);
    document.addEventListener('keydown', onKey);
    $('exposure').addEventListener('input', (e) => {
      state.ev = Number(e.target.value);
      $('exposure-value').textContent = `${state.ev} EV`;
      render();
    });
    $('fit').addEventListener('click', () => {
      fit();
      render();
    });
    for (const canvas of [$('view-compare'), $('view-error')]) {
      canvas.addEventListener('mousemove', (e) => {
        const [cx] = canvasPoint(canvas, e.clientX, e.clientY);
        if (e.buttons === 1 && drag && drag.divider) {
          state.split = Math.min(Math.max(cx / canvas.width, 0), 1);
          $('split').value = String(state.split);
          render();
        } else if (e.buttons === 1 && drag) {
          const r = canvas.getBoundingClientRect();
          state.panX += ((e.clientX - drag.x) * canvas.width) / r.width;
          state.panY += ((e.clientY - drag.y) * canvas.height) / r.height;
          drag = { x: e.clientX, y: e.clientY };
          render();
        }
        readout(...pixelAt(canvas, e.clientX, e.clientY));
      });
      canvas.addEventListener('mousedown', (e) => {
        // Near the divider (compare view, slider mode) a drag moves it; elsewhere it pans.
        const [cx] = canvasPoint(canvas, e.clientX, e.clientY);
        // Within 8 screen pixels, however small the canvas is shown.
        const reach = (8 * canvas.width) / canvas.getBoundingClientRect().width;
        const onDivider = canvas.id === 'view-compare' && state.mode === 'split' && Math.abs(cx - state.split * canvas.width) <= reach;
        drag = { x: e.clientX, y: e.clientY, divider: onDivider };
        armed = true;
        e.preventDefault();
      });
      canvas.addEventListener('mouseleave', () => {
        armed = false;
      });
      // The wheel zooms only after a click on the image or with a modifier held; else the page
      // scrolls as usual.
      canvas.addEventListener('wheel', (e) => {
        if (!(armed || e.ctrlKey || e.shiftKey || e.altKey || e.metaKey)) return;
        e.preventDefault();
        const [cx, cy] = canvasPoint(canvas, e.clientX, e.clientY);
        zoomAt(cx, cy, e.deltaY < 0 ? 1.25 : 0.8);
        render();
      }, { passive: false });
    }
    window.addEventListener('mouseup', () => {
      drag = null;
    });
    // A view's link followed (or the address edited) on the open page.
    window.addEventListener('hashchange', () => {
      const hash = location.hash.slice(1);
      if (!SELFTEST && hash.includes('a=')) restore(hash);
    });
  }
  let drag = null;
  let armed = false;
  // The shots some table row opens.
  const linked = new Set();

  // ---- tables ------------------------------------------------------------------------------
  async function tables() {
    const list = $('table-list');
    const first = DATA.tables.some((u) => u.file === 'summary.csv') ? 'summary.csv' : DATA.tables.length ? DATA.tables[0].file : null;
    for (const t of DATA.tables) {
      const link = document.createElement('a');
      link.href = fileUrl(t.file);
      link.textContent = t.file;
      if (t.packed === null) {
        const p = document.createElement('p');
        p.append(link, ' (too large to show here; open the file)');
        list.append(p);
        continue;
      }
      const { header, rows } = JSON.parse(new TextDecoder().decode(await inflate(t.packed)));
      const details = document.createElement('details');
      details.open = t.file === first;
      const summary = document.createElement('summary');
      summary.append(link, ` (${rows.length} rows)`);
      const table = document.createElement('table');
      table.className = 'data';
      const head = table.createTHead().insertRow();
      const body = table.createTBody();
      const numeric = header.map((_, c) => rows.every((r) => r[c] === '' || Number.isFinite(Number(r[c]))));
      header.forEach((h, c) => {
        const th = document.createElement('th');
        th.textContent = h;
        th.title = 'sort';
        th.addEventListener('click', () => sortBy(body, c, numeric[c], th));
        head.append(th);
      });
      rows.forEach((r) => {
        const tr = body.insertRow();
        r.forEach((v, c) => {
          const td = tr.insertCell();
          td.dataset.raw = v;
          td.textContent = numeric[c] && v.length > 10 ? Number(v).toPrecision(6) : v;
          if (td.textContent !== v) td.title = v;
        });
        // The most specific shot whose key the row holds (a reference keyed by its variant
        // alone must not take the rows of the shots keyed by every column).
        let shot = -1;
        shots.forEach((s, i) => {
          const entries = Object.entries(s.key);
          const holds = entries.length && entries.every(([k, v]) => {
            const c = header.indexOf(k);
            return c >= 0 && r[c] === v;
          });
          if (holds && (shot < 0 || entries.length > Object.keys(shots[shot].key).length)) shot = i;
        });
        if (shot >= 0) {
          linked.add(shot);
          tr.className = 'linked';
          tr.title = `compare ${shots[shot].label}`;
          tr.addEventListener('click', () => {
            choose(shot);
            $('compare').scrollIntoView();
          });
        }
      });
      details.append(summary, table);
      list.append(details);
    }
  }

  function sortBy(body, c, numeric, th) {
    const down = th.dataset.sort !== 'up';
    th.parentNode.querySelectorAll('th').forEach((h) => delete h.dataset.sort);
    th.dataset.sort = down ? 'up' : 'down';
    const rows = Array.from(body.rows);
    const key = (tr) => tr.cells[c].dataset.raw;
    rows.sort((x, y) => {
      const [p, q] = [key(x), key(y)];
      const order = numeric ? (p === '' ? Infinity : Number(p)) - (q === '' ? Infinity : Number(q)) : p.localeCompare(q);
      return down ? order : -order;
    });
    body.append(...rows);
  }

  // ---- plots at full size ------------------------------------------------------------------
  function lightbox() {
    const box = $('lightbox');
    const close = () => {
      box.hidden = true;
      $('lightbox-img').removeAttribute('src');
    };
    for (const img of document.querySelectorAll('#plots img')) {
      img.addEventListener('click', () => {
        $('lightbox-img').src = img.getAttribute('src');
        box.hidden = false;
      });
    }
    box.addEventListener('click', close);
    document.addEventListener('keydown', (e) => {
      if (e.key === 'Escape') close();
    });
  }

  // The page's first pair, and the state the self-test starts from.
  const opened = { a: null, b: null };

  async function main() {
    if (DATA) {
      ({ galleries, shots } = await decode(DATA));
      if (shots.length) {
        wire();
        const hash = location.hash.slice(1);
        const linkedView = !SELFTEST && hash.includes('a=') && restore(hash);
        if (!linkedView) {
          const a = opening();
          state.a = a;
          choose(a);
          fit();
          render();
        }
        opened.a = shots[state.a].exr;
        opened.b = shots[state.b].exr;
      }
      await tables();
    }
    lightbox();
  }

  return {
    main, errors, state, opened, linked, SELFTEST, $,
    get shots() {
      return shots;
    },
    get galleries() {
      return galleries;
    },
    choose, fit, render, partner, pairNumbers, errorLayer, serialise, restore, flipShown, tone, zoomAt,
  };
})();
