// The camera's pane: the binary image the simulator rendered at the last (IMG), which the
// server sends once after each new (IMG) (spec/studio.md, CameraImage), with its scene's
// window (a box) and the centroid (IMG) returned (a cross), as the replay page of
// `rl1c sim --html` draws it; and where the camera looks now (the frame's pan, tilt and
// scene).

import type { CameraImage, Frame } from "./protocol";

const WINDOW = "#0c8", CENTROID = "#f33";

export class CameraPane {
  private image: CameraImage | null = null;
  private frame: Frame | null = null;
  private drawn: CameraImage | null = null;
  private scheduled = false;

  constructor(private readonly pane: HTMLElement, private readonly canvas: HTMLCanvasElement,
              private readonly caption: HTMLElement) {}

  clear(): void {
    this.image = this.frame = this.drawn = null;
    this.draw();
  }

  show(image: CameraImage | null, frame: Frame | null): void {
    if (image) this.image = image;
    if (frame) this.frame = frame;
    if ((image || frame) && !this.scheduled) {
      this.scheduled = true;
      requestAnimationFrame(() => { this.scheduled = false; this.draw(); });
    }
  }

  private draw(): void {
    const { image, frame } = this;
    this.pane.hidden = image === null && frame === null;
    const looks = frame ? `pan ${frame.pan}, tilted ${frame.tilt}, scene ${frame.scene}` : "";
    if (image === null) {
      this.drawn = null;
      this.canvas.getContext("2d")?.clearRect(0, 0, this.canvas.width, this.canvas.height);
      delete this.canvas.dataset.time;
      this.caption.textContent = looks ? `${looks}; no (IMG) yet` : "";
      return;
    }
    if (image !== this.drawn) this.drawImage(image);
    const [area, x, y] = image.reading;
    this.caption.textContent = `${looks ? `${looks}; ` : ""}(IMG) at ${image.time.toFixed(2)} s in scene `
      + `${image.scene}: area ${area}, x ${x}, y ${y} (the cross; the box is the scene's window)`;
  }

  private drawImage(image: CameraImage): void {
    this.drawn = image;
    const [width, height] = image.size;
    if (this.canvas.width !== width) this.canvas.width = width;
    if (this.canvas.height !== height) this.canvas.height = height;
    const context = this.canvas.getContext("2d");
    if (!context) return;
    const pixels = context.createImageData(width, height);
    const bits = atob(image.bits);
    for (let row = 0; row < image.rows; row++) {
      for (let column = 0; column < image.columns; column++) {
        const k = row * image.columns + column;
        if (bits.charCodeAt(k >> 3) & (128 >> (k & 7))) {
          const p = 4 * ((image.top + row) * width + image.left + column);
          pixels.data[p] = pixels.data[p + 1] = pixels.data[p + 2] = 255;
        }
      }
    }
    for (let p = 3; p < pixels.data.length; p += 4) pixels.data[p] = 255;
    context.putImageData(pixels, 0, 0);
    const [x0, y0, x1, y1] = image.window;
    context.strokeStyle = WINDOW;
    context.lineWidth = 1;
    // Round the window, not on it: its edge pixels are measured too.
    context.strokeRect(x0 - 0.5, y0 - 0.5, x1 - x0 + 1, y1 - y0 + 1);
    const [area, x, y] = image.reading;
    if (area > 0) {
      context.strokeStyle = CENTROID;
      context.beginPath();
      context.moveTo(x - 6, y + 0.5); context.lineTo(x + 7, y + 0.5);
      context.moveTo(x + 0.5, y - 6); context.lineTo(x + 0.5, y + 7);
      context.stroke();
    }
    this.canvas.dataset.time = String(image.time);
  }
}
