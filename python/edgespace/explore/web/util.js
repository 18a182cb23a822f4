// util.js — number formatting shared by the page's parts.

// Three significant digits, exponent notation for very small or large values.
export function fmt(x) {
  if (x === null || x === undefined || !isFinite(x)) return '–';
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e4) ? x.toExponential(2) : x.toPrecision(3);
}
