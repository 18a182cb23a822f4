// scatter.js — the PCA scatter of edgespace explore: the rows' scores (in
// standard deviations) on two chosen components as SVG circles coloured by a
// label column; hovering names the row, a click asks for its mesh; a cross
// marks the current slider position.
const SVG = 'http://www.w3.org/2000/svg';
// Tableau 10: distinct hues that stay apart for colour-blind readers
const PALETTE = ['#4e79a7', '#f28e2b', '#e15759', '#76b7b2', '#59a14f', '#edc948',
  '#b07aa1', '#ff9da7', '#9c755f', '#bab0ac'];
const M = { l: 34, r: 8, t: 8, b: 26 };

function el(name, attrs, parent) {
  const e = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (parent) parent.append(e);
  return e;
}

export class Scatter {
  constructor(svg, legend, hover, info, onClick, sx, sy, color) {
    Object.assign(this, { svg, legend, hover, info, onClick, sx, sy, color });
    this.pcs = info.directions.filter((d) => d.kind === 'pc');
    this.pcs.forEach((d, i) => {
      sx.append(new Option(d.label, i));
      sy.append(new Option(d.label, i));
    });
    sy.value = Math.min(1, this.pcs.length - 1);
    color.append(new Option('none', ''));
    for (const c of info.columns) color.append(new Option(c, c));
    color.value = info.color_by || '';
    for (const s of [sx, sy, color]) s.addEventListener('change', () => this.draw());
    this.coords = {};
    this.draw();
  }

  draw() {
    const { svg, info } = this;
    svg.replaceChildren();
    const W = +svg.getAttribute('width'), H = +svg.getAttribute('height');
    const rows = info.rows;
    const i = this.component(+this.sx.value), j = this.component(+this.sy.value);
    if (!this.pcs.length || !rows.ids.length) {
      el('text', { x: 20, y: 40 }, svg).textContent = 'no scores to plot';
      return;
    }
    const xs = rows.scores.map((s) => s[i]), ys = rows.scores.map((s) => s[j]);
    const span = (v) => {
      const a = Math.min(-3, ...v), b = Math.max(3, ...v);
      return [a, b];
    };
    const [x0, x1] = span(xs), [y0, y1] = span(ys);
    this.X = (x) => M.l + (x - x0) / (x1 - x0) * (W - M.l - M.r);
    this.Y = (y) => H - M.b - (y - y0) / (y1 - y0) * (H - M.t - M.b);
    el('line', { class: 'axis', x1: this.X(x0), x2: this.X(x1), y1: this.Y(0), y2: this.Y(0) }, svg);
    el('line', { class: 'axis', x1: this.X(0), x2: this.X(0), y1: this.Y(y0), y2: this.Y(y1) }, svg);
    for (const t of [-3, 3]) {
      el('text', { x: this.X(t) - 6, y: H - 10 }, svg).textContent = t;
      el('text', { x: 4, y: this.Y(t) + 3 }, svg).textContent = t;
    }
    el('text', { x: W / 2 - 40, y: H - 2 }, svg).textContent = `${this.pcs[+this.sx.value].label} (sd)`;
    el('text', { x: 10, y: H / 2 + 40, transform: `rotate(-90 10 ${H / 2 + 40})` }, svg)
      .textContent = `${this.pcs[+this.sy.value].label} (sd)`;
    const col = this.color.value, labels = col ? rows.labels[col] : null;
    const levels = labels ? [...new Set(labels)].sort() : [];
    const colour = (k) => (labels ? PALETTE[levels.indexOf(labels[k]) % PALETTE.length] : PALETTE[0]);
    rows.ids.forEach((id, k) => {
      const c = el('circle', { cx: this.X(xs[k]), cy: this.Y(ys[k]), r: 4, fill: colour(k) }, svg);
      c.dataset.row = id;
      const text = labels ? `${id} (${col} ${labels[k]})` : id;
      el('title', {}, c).textContent = text;
      c.addEventListener('mouseenter', () => { this.hover.textContent = text; });
      c.addEventListener('click', () => this.onClick(id));
    });
    this.legend.replaceChildren(...levels.map((v, k) => {
      const s = document.createElement('span');
      s.style.setProperty('--c', PALETTE[k % PALETTE.length]);
      s.textContent = v;
      return s;
    }));
    this.marker = el('g', {}, svg);
    this.mark(this.coords);
  }

  // The score column of the k-th PC slider (its key is "pcK").
  component(k) { return +this.pcs[k].key.slice(2) - 1; }

  // The current position (slider coordinates {pcK: t}) as a cross.
  mark(coords) {
    this.coords = coords;
    if (!this.marker) return;
    const x = this.X(coords[this.pcs[+this.sx.value].key] || 0);
    const y = this.Y(coords[this.pcs[+this.sy.value].key] || 0);
    this.marker.replaceChildren();
    el('line', { class: 'marker', x1: x - 7, x2: x + 7, y1: y, y2: y }, this.marker);
    el('line', { class: 'marker', x1: x, x2: x, y1: y - 7, y2: y + 7 }, this.marker);
  }
}
