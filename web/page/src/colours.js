// The native viewer's colours (viewer/marker_colors.h), linear RGB 0..1, so the
// page and snapthread-viewer look alike. Shading is the viewer's headlight too
// (scene_view.js: 0.35 + 0.65 |n . eye|).
export const BACKGROUND = [0.11, 0.12, 0.15];

// force_model_t.STATUS_*: marker_colors.h StatusColor.
export function statusColour(status) {
  switch (status) {
    case 0: return [0.55, 0.80, 0.95]; // regular: pale blue
    case 1: return [1.00, 0.62, 0.10]; // near fold: orange
    case 2: return [0.95, 0.20, 0.20]; // snapped: red
    case 4: return [0.85, 0.35, 0.75]; // snapping (time budget): magenta
    default: return [0.55, 0.55, 0.55]; // invalid: grey
  }
}

export const STATUS_NAMES = ['regular', 'near fold', 'snapped', 'invalid', 'snapping'];

export const CLAMP = [0.6, 0.6, 0.62];     // the clamped end
export const GRASP = [1.0, 0.85, 0.2];     // the grasp sphere(s)
export const GRIP = [0.8, 0.4, 0.9];       // the grip direction arrow
export const FORCE = [1.0, 0.35, 0.25];    // the force arrow
export const CONTACT = [0.2, 0.95, 0.6];   // self-contact pairs (not in the native viewer yet)

export function css([r, g, b]) {
  return `rgb(${Math.round(255 * r)}, ${Math.round(255 * g)}, ${Math.round(255 * b)})`;
}
