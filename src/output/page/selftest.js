'use strict';
// The page's self-test, run when the page is opened with #selftest: it hovers every image,
// moves the slider and the divider, toggles, changes the exposure, the error view and its scale,
// presses keys, turns the wheel, round-trips the view through the URL, opens a plot, and writes
// what it found as JSON into the element with id selftest, which the browser test
// (tests/it/common/browser.rs) checks against the files.
(function () {
  const P = PAGE;
  const $ = P.$;
  const state = P.state;

  function canvasHash(c) {
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
  const shownHash = () => canvasHash($('view-compare'));

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

  const centre = (c) => {
    const r = c.getBoundingClientRect();
    return [r.left + r.width / 2, r.top + r.height / 2];
  };

  // Magnifies around pixel (x, y), moves the cursor over its centre, and reads what the page
  // says and draws there: A and B each shown whole at 0 EV and A at +1 EV, the error view.
  function hover(x, y) {
    state.zoom = 4;
    const c = $('view-compare');
    state.panX = c.width / 2 - (x + 0.5) * state.zoom;
    state.panY = c.height / 2 - (y + 0.5) * state.zoom;
    P.render();
    const [clientX, clientY] = centre(c);
    c.dispatchEvent(new MouseEvent('mousemove', { clientX, clientY, bubbles: true }));
    const text = (id) => ($(id) ? $(id).textContent : null);
    const out = { x: text('read-x'), y: text('read-y'), a: text('read-a'), b: text('read-b'), e: text('read-e') };
    const [cx, cy] = [c.width / 2, c.height / 2];
    out.rgb_e = shownAt($('view-error'), cx, cy);
    const saved = { mode: state.mode, showB: state.showB, ev: state.ev };
    const colour = (showB, ev) => {
      Object.assign(state, { mode: 'toggle', showB, ev });
      P.render();
      return shownAt(c, cx, cy);
    };
    Object.assign(out, { rgb_a: colour(false, 0), rgb_b: colour(true, 0), rgb_a_ev1: colour(false, 1) });
    Object.assign(state, saved);
    P.render();
    return out;
  }

  const differs = (i, j) => {
    const [p, q] = [P.shots[i].values, P.shots[j].values];
    return p.length === q.length && p.some((v, k) => v !== q[k]);
  };

  // Another image of i's size with the same values (-1 where there is none).
  const twinOf = (i) => P.shots.findIndex((t, j) => j !== i && t.width === P.shots[i].width && t.height === P.shots[i].height && !differs(i, j));

  const set = (id, value, event = 'change') => {
    $(id).value = String(value);
    $(id).dispatchEvent(new Event(event));
  };

  const key = (target, k) => target.dispatchEvent(new KeyboardEvent('keydown', { key: k, bubbles: true, cancelable: true }));

  // Every image picked as A in its select, against the B that follows it there (another image
  // of its size where that is A itself), and the first bit-identical pair of different images:
  // the values under the cursor, the pair's numbers and captions.
  function readouts() {
    const shots = P.shots;
    const out = [];
    const followed = new Map();
    const pairs = shots.map((s, i) => {
      set('pick-a', i);
      const b = state.b;
      followed.set(i, shots[b].exr);
      return [i, b !== i ? b : shots.findIndex((t, j) => j !== i && t.width === s.width && t.height === s.height)];
    });
    const twin = shots.findIndex((_, i) => twinOf(i) >= 0);
    if (twin >= 0) pairs.push([twin, twinOf(twin)]);
    pairs.forEach(([i, b]) => {
      const s = shots[i];
      P.choose(i, b >= 0 ? b : i);
      set('error-view', 'diff');
      set('scale', 'auto');
      let worst = 0;
      const other = shots[state.b].values;
      s.values.forEach((v, k) => {
        if (Math.abs(v - other[k]) > Math.abs(s.values[worst] - other[worst])) worst = k;
      });
      const numbers = {};
      for (const n of ['mse', 'relmse', 'flip', 'max', 'differ', 'pixels', 'compared']) numbers[n] = $(`num-${n}`).textContent;
      for (const [x, y] of [[0, 0], [s.width - 1, s.height - 1], [worst % s.width, Math.floor(worst / s.width)]]) {
        out.push({
          a: s.exr, b: shots[state.b].exr, followed: followed.get(i), png_a: s.png, png_b: shots[state.b].png, x, y,
          numbers, error_caption: $('error-caption').textContent, shown: hover(x, y),
        });
      }
    });
    return out;
  }

  // Whether any of the page's frame moves while the controls change.
  function layout() {
    const ids = ['view-compare', 'view-error', 'numbers', 'readout', 'compare-caption', 'error-caption', 'colour-scale', 'files'];
    const rects = () => ids.map((id) => {
      const r = $(id).getBoundingClientRect();
      return [r.left, r.top, r.width, r.height].map(Math.round).join(',');
    });
    const shots = P.shots;
    const pairs = [];
    for (let i = 0; i < shots.length && pairs.length < 1; i++) {
      const b = P.partner(i);
      if (b !== i && differs(i, b)) pairs.push([i, b]);
    }
    if (!pairs.length) return [];
    P.choose(...pairs[0]);
    P.fit();
    P.render();
    const base = rects();
    const moved = [];
    const step = (name, act) => {
      act();
      rects().forEach((r, k) => {
        if (r !== base[k]) moved.push(`${name} moves #${ids[k]} (${base[k]} to ${r})`);
      });
    };
    step('relative squared error', () => set('error-view', 'relse'));
    step('log scale', () => set('scale', 'log'));
    step('a user maximum', () => set('scale', 'user'));
    step('the fixed scale', () => set('scale', 'fixed'));
    if (!$('error-view').querySelector('option[value="flip"]').disabled) step('the FLIP view', () => set('error-view', 'flip'));
    step('toggle mode', () => set('mode', 'toggle'));
    step('slider mode', () => set('mode', 'split'));
    step('+3 EV', () => set('exposure', 3, 'input'));
    const longest = shots.reduce((l, s, i) => (s.label.length > shots[l].label.length ? i : l), 0);
    step('A with the longest label', () => set('pick-a', longest));
    const twin = shots.findIndex((_, i) => twinOf(i) >= 0);
    if (twin >= 0) step('a bit-identical pair', () => P.choose(twin, twinOf(twin)));
    set('exposure', 0, 'input');
    set('error-view', 'diff');
    set('scale', 'auto');
    return moved;
  }

  // Number keys move A through its gallery against the pinned B; T toggles even after the
  // slider had the focus.
  function keys() {
    const out = { jump: null, after_slider: null };
    const g = P.galleries.find((x) => x.count >= 2);
    if (g) {
      // B pinned to an image that is not the partner A would get (where there is one).
      const shots = P.shots;
      const partner = P.partner(g.first + 1);
      const other = shots.findIndex((s, j) => j !== partner && j !== g.first + 1 && j !== g.first && P.shots[g.first].width === s.width && P.shots[g.first].height === s.height);
      const b = other >= 0 ? other : partner;
      P.choose(g.first, b);
      key(document.body, '2');
      out.jump = state.a === g.first + 1 && state.b === b;
    }
    set('mode', 'split');
    $('split').focus();
    key($('split'), 't');
    out.after_slider = state.mode === 'toggle';
    $('split').blur();
    set('mode', 'split');
    return out;
  }

  // The wheel zooms only after a click or with a modifier, and between bounds.
  function wheel() {
    const c = $('view-compare');
    P.fit();
    P.render();
    c.dispatchEvent(new MouseEvent('mouseleave'));
    const [clientX, clientY] = centre(c);
    const turn = (deltaY, ctrlKey) => {
      const e = new WheelEvent('wheel', { deltaY, ctrlKey, clientX, clientY, bubbles: true, cancelable: true });
      c.dispatchEvent(e);
      return e.defaultPrevented;
    };
    const z0 = state.zoom;
    const plain = turn(-100, false);
    const out = { plain_ignored: !plain && state.zoom === z0 };
    turn(-100, true);
    out.modifier_zooms = state.zoom > z0;
    for (let k = 0; k < 200; k++) turn(-100, true);
    out.most = state.zoom;
    for (let k = 0; k < 400; k++) turn(100, true);
    out.least = state.zoom;
    out.fit = z0;
    P.fit();
    P.render();
    return out;
  }

  // Dragging the divider on the image moves it.
  function divider() {
    const c = $('view-compare');
    set('mode', 'split');
    set('split', 0.5, 'input');
    const r = c.getBoundingClientRect();
    const x = r.left + r.width / 2;
    const y = r.top + r.height / 2;
    c.dispatchEvent(new MouseEvent('mousedown', { clientX: x, clientY: y, buttons: 1, bubbles: true }));
    c.dispatchEvent(new MouseEvent('mousemove', { clientX: x + r.width / 4, clientY: y, buttons: 1, bubbles: true }));
    window.dispatchEvent(new MouseEvent('mouseup'));
    const out = { split: state.split };
    set('split', 0.5, 'input');
    return out;
  }

  // The FLIP view is offered only where A's map is against B.
  function flipOffered() {
    const shots = P.shots;
    const wrong = [];
    shots.forEach((s, i) => {
      const g = P.galleries[s.gallery];
      for (const j of [g.reference, P.partner(i)]) {
        if (j === null || j === i) continue;
        P.choose(i, j);
        const offered = !$('error-view').querySelector('option[value="flip"]').disabled;
        const against = s.flip !== null && g.reference === j;
        if (offered !== against) wrong.push(`${s.exr} against ${shots[j].exr}: FLIP ${offered ? 'offered' : 'not offered'}`);
      }
    });
    return wrong;
  }

  // The URL's view opens the same pair and settings, every one of them changed in between, and
  // the controls show them.
  function hash() {
    const shots = P.shots;
    const reset = () => {
      set('mode', 'split');
      set('exposure', 0, 'input');
      set('split', 0.5, 'input');
      set('error-view', 'diff');
      set('scale', 'auto');
      P.fit();
      P.render();
    };
    set('mode', 'toggle');
    set('exposure', 1, 'input');
    set('split', 0.25, 'input');
    set('error-view', 'relse');
    set('scale', 'log');
    P.zoomAt(10, 10, 1.25);
    P.render();
    const saved = P.serialise();
    P.choose(shots.length - 1);
    reset();
    P.restore(saved);
    const shown = [$('mode').value, Number($('exposure').value), Number($('split').value), $('error-view').value, $('scale').value];
    const ok = P.serialise() === saved && JSON.stringify(shown) === JSON.stringify([state.mode, state.ev, state.split, state.view, state.scale]);
    reset();
    return { ok, saved, shown };
  }

  async function plotAtFullSize() {
    const img = document.querySelector('#plots img');
    if (!img) return null;
    img.click();
    const big = $('lightbox-img');
    await big.decode().catch(() => null);
    const out = { open: !$('lightbox').hidden, natural: big.naturalWidth, shown: Math.round(big.getBoundingClientRect().width) };
    $('lightbox').click();
    return out;
  }

  async function selftest() {
    const shots = P.shots;
    const report = {
      errors: P.errors, opened: P.opened, images: [], readouts: [], slider: null, toggle: null, exposure: null,
      shots: shots.length, layout: [], keys: null, wheel: null, divider: null, flip_offered: [], hash: null, plot: null,
    };
    // A shot that names its table rows (its key) and that no row opens.
    report.unlinked = shots.filter((s, i) => Object.keys(s.key).length && !P.linked.has(i)).map((s) => s.exr);
    if (document.readyState !== 'complete') await new Promise((done) => window.addEventListener('load', done));
    // A broken image has no natural size, and drawing it throws.
    const scratch = document.createElement('canvas').getContext('2d');
    for (const img of document.querySelectorAll('img[src]')) {
      let ok = img.complete && img.naturalWidth > 0;
      try {
        scratch.drawImage(img, 0, 0, 1, 1);
      } catch (e) {
        ok = false;
      }
      report.images.push({ src: img.getAttribute('src'), ok });
    }
    report.plot = await plotAtFullSize();
    if (shots.length) {
      report.readouts = readouts();
      report.layout = layout();
      report.keys = keys();
      report.wheel = wheel();
      report.divider = divider();
      report.flip_offered = flipOffered();
      report.hash = hash();
      let pair = null;
      for (let i = 0; i < shots.length && !pair; i++) {
        for (let j = 0; j < shots.length && !pair; j++) if (i !== j && shots[i].width === shots[j].width && shots[i].height === shots[j].height && differs(i, j)) pair = [i, j];
      }
      if (pair) {
        P.choose(pair[0], pair[1]);
        P.fit();
        set('mode', 'split');
        const slide = (v) => {
          set('split', v, 'input');
          return shownHash();
        };
        report.slider = { a: shots[pair[0]].exr, b: shots[pair[1]].exr, changed: slide(1) !== slide(0) };
        const before = shownHash();
        $('toggle').click();
        const once = shownHash();
        $('toggle').click();
        report.toggle = { changed: before !== once && once !== shownHash() };
        const expose = (ev) => {
          set('exposure', ev, 'input');
          return shownHash();
        };
        report.exposure = { changed: expose(-1) !== expose(0) };
      }
    }
    const out = $('selftest');
    out.textContent = JSON.stringify(report);
    out.hidden = false;
  }

  P.main()
    .then(() => (P.SELFTEST ? selftest() : null))
    .catch((e) => {
      P.errors.push(String(e && e.stack ? e.stack : e));
      if (P.SELFTEST) {
        $('selftest').textContent = JSON.stringify({ errors: P.errors });
        $('selftest').hidden = false;
      }
    });
})();
