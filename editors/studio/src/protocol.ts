// The studio's protocol (spec/studio.md, "/studio"): JSON-RPC 2.0 over a WebSocket, one
// message a text frame, and the shapes of its data as that page gives them.

export type Point = [number, number];
/** x, y (cm), heading (degrees, counterclockwise from +x). */
export type Pose = [number, number, number];

export interface Hello {
  version: string;
  folder: string;
  rootUri: string;
  program: string | null;
  world: string | null;
  levels: number[];
  defaultLevel: number;
  maxFramesPerSecond: number;
}

export interface FileEntry { path: string; kind: "program" | "world" | "sensors"; size: number }
export interface FileText { path: string; text: string; encoding: "utf-8" | "cp932" }

export interface Param { name: string; low: number; high: number; meaning: string }
export interface Form {
  selector: string | null;
  summary: string;
  params: Param[];
  result: string | null;
  writes: string[];
  snippet: string;
}
export interface Builtin {
  mnemonic: string;
  name: string;
  group: string;
  waits: boolean;
  /** What each value of a reading of several is, in order (IMG: area, x, y, angle). */
  readings: string[];
  forms: Form[];
}

interface Named { name: string; points: Point[] }
export interface Geometry {
  floor: Point;
  start: Pose;
  vehicle: { length: number; width: number; cameraAhead: number };
  lines: (Named & { width: number })[];
  marks: Named[];
  stands: { name: string; corners: Point[]; marker: Point; facing: number }[];
  walls: Named[];
  obstacles: Named[];
  goal: null | {
    reach: Named[];
    holds: { stand: string; marker: Point; within: number }[];
    end: Named | null;
    avoid: Named[];
    deadline: number | null;
  };
}

export interface ConfigProblem { line: number | null; message: string }
export interface WorldCheck { errors: ConfigProblem[]; geometry: Geometry | null }

export interface Frame {
  time: number;
  line: number | null;
  pose: Pose;
  wheels: [number, number];
  steering: number;
  pan: number;
  tilt: "up" | "down";
  mode: number;
  scene: number;
}

export interface TraceEntry {
  time: number;
  call: string;
  args: number[];
  result?: number[];
  line: number | null;
  pose?: Pose;
  text: string;
}

/** The binary image the simulator rendered at an (IMG): the part from column `left` and
 * row `top`, `columns` by `rows`, its pixels row by row packed eight to a byte (the
 * first in the high bit), base64; `window` x0, y0, x1, y1 (end exclusive). */
export interface CameraImage {
  time: number;
  scene: number;
  size: [number, number];
  left: number;
  top: number;
  columns: number;
  rows: number;
  bits: string;
  window: [number, number, number, number];
  reading: [number, number, number];
}

export interface RunEvent { time: number; kind: "lost" | "found" | "handler" | "fault" | "end"; text: string; pose: Point }

/** What every notification of a run carries since the one before: `image` only after a
 * new (IMG). */
export interface Progress { frame: Frame | null; trace: TraceEntry[]; events: RunEvent[]; image: CameraImage | null }

export interface Stopped extends Progress {
  reason: "entry" | "step" | "breakpoint" | "call" | "lost-line" | "pause";
  line: number | null;
  text: string;
  variables: Record<string, number>;
  changed: string[];
  device: Record<string, unknown>;
}

export interface Ended extends Progress {
  status: { code: string; exit_status: number; message: string; line: number | null } | null;
  variables: Record<string, number>;
  instructions: number;
  deviceTime: number;
  goal: { met: boolean } | null;
}

export interface Binding { line: number; boundTo: number | null; condition: string | null; verified: boolean; message?: string }
export interface Launched { breakpoints: Binding[]; calls: unknown[]; lines: number[] }

/** A diagnostic of `rl1c check --format json`, as -32003's data lists them. */
export interface CheckDiagnostic { line: number; column: number; severity: string; code: string; message: string }

/** An error answer, with its code and data. */
export class StudioError extends Error {
  constructor(message: string, readonly code: number, readonly data: unknown) {
    super(message);
  }
}

export const PROGRAM_HAS_ERRORS = -32003;
export const INVALID_CONFIGURATION = -32004;

type Handler = (params: any) => void;

/** The connection: requests answered by id, and notifications to their handlers. */
export class StudioConnection {
  private nextId = 1;
  private readonly waiting = new Map<number, { resolve: (value: any) => void; reject: (error: Error) => void }>();
  private readonly handlers = new Map<string, Handler>();

  constructor(private readonly socket: WebSocket, private readonly lost: (why: string) => void) {
    socket.addEventListener("message", (event) => this.receive(String(event.data)));
    socket.addEventListener("close", (event) => {
      for (const { reject } of this.waiting.values()) reject(new Error("the studio's server is gone"));
      this.waiting.clear();
      lost(event.reason || "the studio's server closed the connection: start `rl1c studio` again");
    });
  }

  on(method: string, handler: Handler): void {
    this.handlers.set(method, handler);
  }

  request<T>(method: string, params: object = {}): Promise<T> {
    const id = this.nextId++;
    return new Promise<T>((resolve, reject) => {
      this.waiting.set(id, { resolve, reject });
      this.socket.send(JSON.stringify({ jsonrpc: "2.0", id, method, params }));
    });
  }

  private receive(text: string): void {
    let message;
    try {
      message = JSON.parse(text);
    } catch {
      this.lost(`the studio's server sent something that is not JSON (${text.slice(0, 40)}): please report it`);
      return;
    }
    if (typeof message.id === "number" && this.waiting.has(message.id)) {
      const { resolve, reject } = this.waiting.get(message.id)!;
      this.waiting.delete(message.id);
      if (message.error) {
        reject(new StudioError(String(message.error.message), message.error.code, message.error.data));
      } else {
        resolve(message.result);
      }
    } else if (typeof message.method === "string") {
      this.handlers.get(message.method)?.(message.params);
    }
  }
}
