'use strict';
// The comparison page's viewer. It reads window.PENUMBRA (page_data.js, written beside the
// page): galleries of measured images and the results folder's tables. Opened with
// #selftest it also checks itself and writes what it found as JSON into the element with id
// selftest, which the browser test reads.
(function () {
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
  const NO_RECEIVER = -1;
  const NO_RECEIVER_RGB = [20, 24, 60];
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

  // Every shot as {label, gallery, width, height, tone, values: Float32Array, flip: Float32Array|null}.
  async function decode(data) {
    const shots = [];
    for (const [g, gallery] of data.galleries.entries()) {
      const first = shots.length;
      for (const s of gallery.shots) {
        const n = gallery.width * gallery.height;
        let values;
        if (s.same !== null) {
          values = shots[first + s.same].values;
        } else {
          const bytes = await inflate(s.data);
          if (bytes.length !== 4 * n) throw new Error(`${s.exr}: ${bytes.length} bytes for ${n} pixels`);
          const view = new DataView(bytes.buffer);
          values = new Float32Array(n);
          for (let i = 0; i < n; i++) values[i] = view.getFloat32(4 * i, true);
        }
        let flip = null;
        if (s.flip !== null) {
          const bytes = await inflate(s.flip);
          if (bytes.length !== n) throw new Error(`${s.exr}: FLIP map of ${bytes.length} pixels for ${n}`);
          flip = Float32Array.from(bytes, (b) => b / 255);
        }
        shots.push({
          label: s.label, exr: s.exr, png: s.png, key: s.key, gallery: g,
          galleryTitle: gallery.title, reference: gallery.reference === null ? null : first + gallery.reference,
          width: gallery.width, height: gallery.height, tone: gallery.tone, values, flip,
        });
      }
    }
    return shots;
  }

  // ---- colour ------------------------------------------------------------------------------
  const toByte = (x) => Math.round(Math.min(Math.max(x, 0), 1) * 255);

  // The same mapping as the PNG beside each EXR (output/images.rs), scaled by 2^ev.
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

  // ---- error views -------------------------------------------------------------------------
  const VIEWS = {
    diff: { name: 'A − B', value: (a, b) => a - b, colour: (v, s) => diverging(v / s), lo: (s) => -s },
    relse: { name: '(A − B)² / (B² + 0.01)', value: (a, b) => ((a - b) * (a - b)) / (b * b + 0.01), colour: (v, s) => magma(v / s), lo: () => 0 },
    flip: { name: 'FLIP', value: null, colour: (v) => magma(v), lo: () => 0 },
  };

  // Per pixel the error view's value (NaN where a pixel has no receiver or there is no map).
  function errorValues(view, a, b) {
    const n = a.values.length;
    const out = new Float64Array(n).fill(NaN);
    if (view === 'flip') {
      if (a.flip) out.set(a.flip);
      return out;
    }
    if (b.values.length !== n) return out;
    const f = VIEWS[view].value;
    for (let i = 0; i < n; i++) {
      const x = a.values[i];
      const y = b.values[i];
      if (x !== NO_RECEIVER && y !== NO_RECEIVER) out[i] = f(x, y);
    }
    return out;
  }

  // The colour scale of an error view: the 99th percentile of |value| (FLIP: 1).
  function errorScale(view, values) {
    if (view === 'flip') return 1;
    const m = Array.from(values, Math.abs).filter(Number.isFinite).sort((x, y) => x - y);
    const s = m.length ? m[Math.min(m.length - 1, Math.floor(0.99 * m.length))] : 0;
    return s > 0 ? s : 1;
  }

  // ---- the viewer --------------------------------------------------------------------------
  const state = { a: 0, b: 0, mode: 'split', split: 0.5, showB: false, ev: 0, view: 'diff', zoom: 1, panX: 0, panY: 0 };
  let shots = [];
  const layers = new Map();

  function layer(shot, key, paint) {
    const id = `${shots.indexOf(shot)}:${key}`;
    if (!layers.has(id)) {
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

  function picture(shot) {
    const gain = Math.pow(2, state.ev);
    return layer(shot, `ev${state.ev}`, (px) => {
      shot.values.forEach((v, i) => {
        const rgb = v === NO_RECEIVER && shot.tone.kind === 'linear' ? NO_RECEIVER_RGB : [toneByte(shot.tone, v, gain)].flatMap((x) => [x, x, x]);
        px.set([...rgb, 255], 4 * i);
      });
    });
  }

  let errorCache = null;
  function errorLayer() {
    const a = shots[state.a];
    const b = shots[state.b];
    const key = `${state.a}/${state.b}/${state.view}`;
    if (!errorCache || errorCache.key !== key) {
      const values = errorValues(state.view, a, b);
      const scale = errorScale(state.view, values);
      const c = document.createElement('canvas');
      c.width = a.width;
      c.height = a.height;
      const ctx = c.getContext('2d');
      const img = ctx.createImageData(a.width, a.height);
      values.forEach((v, i) => img.data.set([...(Number.isFinite(v) ? VIEWS[state.view].colour(v, scale) : [96, 96, 96]), 255], 4 * i));
      ctx.putImageData(img, 0, 0);
      errorCache = { key, values, scale, canvas: c };
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

  function render() {
    if (!shots.length) return;
    const a = shots[state.a];
    const b = shots[state.b];
    const compare = $('view-compare');
    draw(compare, (ctx) => {
      if (state.mode === 'flip') {
        ctx.drawImage(picture(state.showB ? b : a), 0, 0);
        return;
      }
      const x = (state.split * compare.width - state.panX) / state.zoom;
      ctx.save();
      ctx.beginPath();
      ctx.rect(-1e6, -1e6, x + 1e6, 2e6);
      ctx.clip();
      ctx.drawImage(picture(a), 0, 0);
      ctx.restore();
      ctx.save();
      ctx.beginPath();
      ctx.rect(x, -1e6, 2e6, 2e6);
      ctx.clip();
      ctx.drawImage(picture(b), 0, 0);
      ctx.restore();
    });
    if (state.mode === 'split') {
      const ctx = compare.getContext('2d');
      ctx.fillStyle = '#ffd400';
      ctx.fillRect(Math.round(state.split * compare.width) - 1, 0, 2, compare.height);
    }
    $('compare-caption').textContent = state.mode === 'flip'
      ? `showing ${state.showB ? 'B' : 'A'}: ${(state.showB ? b : a).label}`
      : `left of the line A: ${a.label}; right B: ${b.label}`;
    const e = errorLayer();
    draw($('view-error'), (ctx) => ctx.drawImage(e.canvas, 0, 0));
    colourBar(e.scale);
    const v = VIEWS[state.view];
    $('error-caption').textContent = state.view === 'flip'
      ? (a.flip ? `FLIP of A against ${shots[a.reference].label}` : 'no FLIP map for A (it is its gallery\'s reference, or the gallery has none)')
      : `${v.name}, scale: 99th percentile of |value|`;
    $('files').innerHTML = '';
    for (const s of [a, b]) {
      for (const f of [s.exr, s.png]) {
        const link = document.createElement('a');
        link.href = fileUrl(f);
        link.textContent = f;
        $('files').append(link, ' ');
      }
    }
  }

  function colourBar(scale) {
    const bar = $('colour-bar');
    const ctx = bar.getContext('2d');
    const v = VIEWS[state.view];
    const lo = v.lo(scale);
    for (let x = 0; x < bar.width; x++) {
      const t = lo + ((scale - lo) * (x + 0.5)) / bar.width;
      ctx.fillStyle = `rgb(${v.colour(t, scale).join(',')})`;
      ctx.fillRect(x, 0, 1, bar.height);
    }
    $('bar-lo').textContent = lo.toPrecision(3);
    $('bar-hi').textContent = scale.toPrecision(3);
  }

  function fit() {
    const a = shots[state.a];
    const c = $('view-compare');
    state.zoom = Math.min(c.width / a.width, c.height / a.height);
    if (state.zoom >= 1) state.zoom = Math.floor(state.zoom);
    state.panX = (c.width - a.width * state.zoom) / 2;
    state.panY = (c.height - a.height * state.zoom) / 2;
  }

  // ---- pixel readout -----------------------------------------------------------------------
  // A pixel's value; an error view's value (NaN where either pixel has no receiver: an error of
  // exactly -1, black against white, is a value), FLIP to the three decimals its map keeps.
  const show = (v) => (v === NO_RECEIVER ? 'no receiver' : Number.isFinite(v) ? v.toPrecision(7) : '—');
  const showError = (v) => (!Number.isFinite(v) ? '—' : state.view === 'flip' ? v.toFixed(3) : v.toPrecision(7));

  function pixelAt(canvas, clientX, clientY) {
    const r = canvas.getBoundingClientRect();
    const cx = ((clientX - r.left) * canvas.width) / r.width;
    const cy = ((clientY - r.top) * canvas.height) / r.height;
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
    const pickA = $('pick-a');
    const pickB = $('pick-b');
    const options = (select, keep) => {
      select.innerHTML = '';
      let group = null;
      shots.forEach((s, i) => {
        if (!keep(s)) return;
        if (!group || group.label !== s.galleryTitle) {
          group = document.createElement('optgroup');
          group.label = s.galleryTitle;
          select.append(group);
        }
        group.append(new Option(s.label, String(i)));
      });
    };
    options(pickA, () => true);
    const a = shots[state.a];
    options(pickB, (s) => s.width === a.width && s.height === a.height);
    pickA.value = String(state.a);
    pickB.value = String(state.b);
  }

  function choose(a, b) {
    const s = shots[a];
    const same = (k) => shots[k] && shots[k].width === s.width && shots[k].height === s.height;
    const newSize = !same(state.a);
    state.a = a;
    if (b !== undefined && same(b)) state.b = b;
    else if (!same(state.b)) state.b = s.reference !== null ? s.reference : a;
    if (newSize) fit();
    fillPicks();
    render();
  }

  function wire() {
    $('pick-a').addEventListener('change', (e) => choose(Number(e.target.value)));
    $('pick-b').addEventListener('change', (e) => choose(state.a, Number(e.target.value)));
    $('mode').addEventListener('change', (e) => {
      state.mode = e.target.value;
      $('split-label').hidden = state.mode !== 'split';
      render();
    });
    $('split').addEventListener('input', (e) => {
      state.split = Number(e.target.value);
      render();
    });
    const flip = () => {
      if (state.mode !== 'flip') {
        state.mode = 'flip';
        $('mode').value = 'flip';
        $('split-label').hidden = true;
        state.showB = true;
      } else {
        state.showB = !state.showB;
      }
      render();
    };
    $('flip').addEventListener('click', flip);
    document.addEventListener('keydown', (e) => {
      if ((e.key === 'f' || e.key === 'F') && e.target.tagName !== 'INPUT' && e.target.tagName !== 'SELECT') flip();
    });
    $('exposure').addEventListener('input', (e) => {
      state.ev = Number(e.target.value);
      $('exposure-value').textContent = `${state.ev} EV`;
      render();
    });
    $('error-view').addEventListener('change', (e) => {
      state.view = e.target.value;
      render();
    });
    $('fit').addEventListener('click', () => {
      fit();
      render();
    });
    for (const canvas of [$('view-compare'), $('view-error')]) {
      canvas.addEventListener('mousemove', (e) => {
        if (e.buttons === 1 && drag) {
          const r = canvas.getBoundingClientRect();
          state.panX += ((e.clientX - drag.x) * canvas.width) / r.width;
          state.panY += ((e.clientY - drag.y) * canvas.height) / r.height;
          drag = { x: e.clientX, y: e.clientY };
          render();
        }
        readout(...pixelAt(canvas, e.clientX, e.clientY));
      });
      canvas.addEventListener('mousedown', (e) => {
        drag = { x: e.clientX, y: e.clientY };
        e.preventDefault();
      });
      canvas.addEventListener('wheel', (e) => {
        e.preventDefault();
        const r = canvas.getBoundingClientRect();
        const cx = ((e.clientX - r.left) * canvas.width) / r.width;
        const cy = ((e.clientY - r.top) * canvas.height) / r.height;
        const factor = e.deltaY < 0 ? 1.25 : 0.8;
        state.panX = cx - (cx - state.panX) * factor;
        state.panY = cy - (cy - state.panY) * factor;
        state.zoom *= factor;
        render();
      }, { passive: false });
    }
    window.addEventListener('mouseup', () => {
      drag = null;
    });
  }
  let drag = null;
  // The shots some table row opens.
  const linked = new Set();

  // ---- tables ------------------------------------------------------------------------------
  function tables() {
    const list = $('table-list');
    DATA.tables.forEach((t) => {
      const details = document.createElement('details');
      details.open = t.file === (DATA.tables.some((u) => u.file === 'summary.csv') ? 'summary.csv' : DATA.tables[0].file);
      const summary = document.createElement('summary');
      const link = document.createElement('a');
      link.href = fileUrl(t.file);
      link.textContent = t.file;
      if (!t.shown) {
        const p = document.createElement('p');
        p.append(link, ' (too large to show here; open the file)');
        list.append(p);
        return;
      }
      summary.append(link, ` (${t.rows.length} rows)`);
      const table = document.createElement('table');
      table.className = 'data';
      const head = table.createTHead().insertRow();
      const body = table.createTBody();
      const numeric = t.header.map((_, c) => t.rows.every((r) => r[c] === '' || Number.isFinite(Number(r[c]))));
      t.header.forEach((h, c) => {
        const th = document.createElement('th');
        th.textContent = h;
        th.title = 'sort';
        th.addEventListener('click', () => sortBy(t, body, c, numeric[c], th));
        head.append(th);
      });
      t.rows.forEach((r) => {
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
            const c = t.header.indexOf(k);
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
    });
  }

  function sortBy(t, body, c, numeric, th) {
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

  // ---- self-test (#selftest) ---------------------------------------------------------------
  function shownHash() {
    const c = $('view-compare');
    const copy = document.createElement('canvas');
    copy.width = c.width;
    copy.height = c.height;
    const ctx = copy.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(c, 0, 0);
    const px = ctx.getImageData(0, 0, c.width, c.height).data;
    let h = 2166136261;
    for (let i = 0; i < px.length; i++) h = Math.imul(h ^ px[i], 16777619) >>> 0;
    return h;
  }

  function hover(x, y) {
    // Magnify around the pixel, then move the cursor over its centre.
    state.zoom = 4;
    const c = $('view-compare');
    state.panX = c.width / 2 - (x + 0.5) * state.zoom;
    state.panY = c.height / 2 - (y + 0.5) * state.zoom;
    render();
    const r = c.getBoundingClientRect();
    const [clientX, clientY] = [r.left + r.width / 2, r.top + r.height / 2];
    c.dispatchEvent(new MouseEvent('mousemove', { clientX, clientY, bubbles: true }));
    const text = (id) => ($(id) ? $(id).textContent : null);
    const out = { x: text('read-x'), y: text('read-y'), a: text('read-a'), b: text('read-b'), e: text('read-e') };
    // What is drawn under the cursor: the error view there, and A and B each shown whole (flip),
    // at 0 EV (the PNG's picture) and at +1 EV.
    const [cx, cy] = [((clientX - r.left) * c.width) / r.width, ((clientY - r.top) * c.height) / r.height];
    out.rgb_e = shownAt($('view-error'), cx, cy);
    const saved = { mode: state.mode, showB: state.showB, ev: state.ev };
    const colour = (showB, ev) => {
      Object.assign(state, { mode: 'flip', showB, ev });
      render();
      return shownAt(c, cx, cy);
    };
    Object.assign(out, { rgb_a: colour(false, 0), rgb_b: colour(true, 0), rgb_a_ev1: colour(false, 1) });
    Object.assign(state, saved);
    render();
    return out;
  }

  // The colour a canvas shows at canvas position (x, y), read from a copy (reading the shown
  // canvas itself makes the browser warn about repeated readbacks).
  function shownAt(canvas, x, y) {
    const copy = document.createElement('canvas');
    copy.width = 1;
    copy.height = 1;
    const ctx = copy.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(canvas, Math.floor(x), Math.floor(y), 1, 1, 0, 0, 1, 1);
    return Array.from(ctx.getImageData(0, 0, 1, 1).data.slice(0, 3));
  }

  function differs(i, j) {
    const [p, q] = [shots[i].values, shots[j].values];
    return p.length === q.length && p.some((v, k) => v !== q[k]);
  }

  async function selftest() {
    const report = { errors, images: [], readouts: [], slider: null, flip: null, exposure: null, shots: shots.length };
    // A shot that names its table rows (its key) and that no row opens.
    report.unlinked = shots.filter((s, i) => Object.keys(s.key).length && !linked.has(i)).map((s) => s.exr);
    if (document.readyState !== 'complete') await new Promise((done) => window.addEventListener('load', done));
    // A broken image has no natural size, and drawing it throws.
    const scratch = document.createElement('canvas').getContext('2d');
    for (const img of document.images) {
      let ok = img.complete && img.naturalWidth > 0;
      try {
        scratch.drawImage(img, 0, 0, 1, 1);
      } catch (e) {
        ok = false;
      }
      report.images.push({ src: img.getAttribute('src'), ok });
    }
    if (shots.length) {
      $('error-view').value = 'diff';
      state.view = 'diff';
      shots.forEach((s, i) => {
        const b = s.reference !== null && s.reference !== i ? s.reference : shots.findIndex((t, j) => j !== i && t.width === s.width && t.height === s.height);
        choose(i, b >= 0 ? b : i);
        let worst = 0;
        const other = shots[state.b].values;
        s.values.forEach((v, k) => {
          if (Math.abs(v - other[k]) > Math.abs(s.values[worst] - other[worst])) worst = k;
        });
        const pixels = [[0, 0], [s.width - 1, s.height - 1], [worst % s.width, Math.floor(worst / s.width)]];
        for (const [x, y] of pixels) {
          report.readouts.push({ a: s.exr, b: shots[state.b].exr, png_a: s.png, png_b: shots[state.b].png, tone: s.tone, x, y, shown: hover(x, y) });
        }
      });
      let pair = null;
      for (let i = 0; i < shots.length && !pair; i++) {
        for (let j = 0; j < shots.length && !pair; j++) if (i !== j && differs(i, j)) pair = [i, j];
      }
      if (pair) {
        choose(pair[0], pair[1]);
        fit();
        $('mode').value = 'split';
        $('mode').dispatchEvent(new Event('change'));
        const slide = (v) => {
          $('split').value = String(v);
          $('split').dispatchEvent(new Event('input'));
          return shownHash();
        };
        report.slider = { a: shots[pair[0]].exr, b: shots[pair[1]].exr, changed: slide(1) !== slide(0) };
        const before = shownHash();
        $('flip').click();
        const once = shownHash();
        $('flip').click();
        report.flip = { changed: before !== once && once !== shownHash() };
        const expose = (ev) => {
          $('exposure').value = String(ev);
          $('exposure').dispatchEvent(new Event('input'));
          return shownHash();
        };
        report.exposure = { changed: expose(-1) !== expose(0) };
      }
    }
    const out = $('selftest');
    out.textContent = JSON.stringify(report);
    out.hidden = false;
  }

  async function main() {
    if (DATA) {
      shots = await decode(DATA);
      if (shots.length) {
        wire();
        // B opens as A's reference, or where its gallery has none (a strip's frames) as the
        // gallery's next image, so that the page opens on a comparison.
        const first = shots[0];
        const next = shots.findIndex((s, j) => j > 0 && s.gallery === first.gallery);
        choose(0, first.reference !== null ? first.reference : next >= 0 ? next : undefined);
        fit();
        render();
      }
      tables();
    }
    if (location.hash === '#selftest') await selftest();
  }
  main().catch((e) => {
    errors.push(String(e && e.stack ? e.stack : e));
    if (location.hash === '#selftest') {
      $('selftest').textContent = JSON.stringify({ errors });
      $('selftest').hidden = false;
    }
  });
})();
