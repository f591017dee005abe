// Colour scales shared by the views.

/** A distinct colour for category i (golden-angle hues, fixed saturation and lightness). */
export function categorical(i) {
  const h = ((i * 137.508) % 360) / 360;
  return hsl(h, 0.62, 0.58);
}

export function hsl(h, s, l) {
  const f = (n) => {
    const k = (n + h * 12) % 12;
    const a = s * Math.min(l, 1 - l);
    return l - a * Math.max(-1, Math.min(k - 3, 9 - k, 1));
  };
  return [f(0), f(8), f(4)];
}

// A perceptually even ramp (dark blue → teal → yellow), sampled at a few stops.
const STOPS = [[0.18, 0.2, 0.55], [0.13, 0.45, 0.62], [0.16, 0.66, 0.52], [0.55, 0.8, 0.3], [0.98, 0.85, 0.2]];

export function ramp(t) {
  const x = Math.max(0, Math.min(1, Number.isFinite(t) ? t : 0)) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(x));
  const f = x - i;
  return STOPS[i].map((v, k) => v + (STOPS[i + 1][k] - v) * f);
}

/** Diverging: blue for negative (gap), grey at 0, red for positive (overlap). */
export function diverging(t) {
  const x = Math.max(-1, Math.min(1, t));
  const mid = [0.75, 0.78, 0.8];
  const end = x < 0 ? [0.2, 0.45, 0.9] : [0.9, 0.3, 0.25];
  const a = Math.abs(x);
  return mid.map((v, k) => v + (end[k] - v) * a);
}

export function css(c) {
  return `rgb(${c.map((v) => Math.round(v * 255)).join(',')})`;
}

export function rampCss() {
  return `linear-gradient(90deg, ${STOPS.map((c, i) => `${css(c)} ${(100 * i) / (STOPS.length - 1)}%`).join(', ')})`;
}
