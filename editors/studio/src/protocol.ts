// The studio's protocol (spec/studio.md): the page's one connection to the server besides
// the language server's, a WebSocket of JSON messages, and the shapes of its data.

export type Point = [number, number];

export interface Param { name: string; low: number; high: number; meaning: string }
export interface Form { selector: string | null; params: Param[]; summary: string; result: string | null; writes: string[] }
export interface Builtin { mnemonic: string; name: string; group: string; forms: Form[] }

export interface Geometry {
  floor: Point;
  start: Frame;
  lines: { name: string; width: number; points: Point[] }[];
  marks: { name: string; points: Point[] }[];
  blocks: { name: string; points: Point[] }[];
  stands: { name: string; corners: Point[]; marker: Point }[];
  vehicle: { outline: Point[] };
}

export interface Frame { time: number; x: number; y: number; heading: number }

export interface Stopped {
  reason: string;
  line: number | null;
  text: string;
  variables: Record<string, number>;
  changed: string[];
  device: Record<string, unknown>;
  trace: TraceLine[];
}

export interface TraceLine { text: string; kind: string; line: number | null }

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
      this.lost(event.reason || "the studio's server closed the connection");
    });
  }

  on(method: string, handler: Handler): void {
    this.handlers.set(method, handler);
  }

  request<T>(method: string, params: object = {}): Promise<T> {
    const id = this.nextId++;
    return new Promise<T>((resolve, reject) => {
      this.waiting.set(id, { resolve, reject });
      this.socket.send(JSON.stringify({ id, method, params }));
    });
  }

  private receive(text: string): void {
    const message = JSON.parse(text);
    if (typeof message.id === "number" && this.waiting.has(message.id)) {
      const { resolve, reject } = this.waiting.get(message.id)!;
      this.waiting.delete(message.id);
      if (message.error) reject(new Error(message.error.message ?? String(message.error)));
      else resolve(message.result);
    } else if (typeof message.method === "string") {
      this.handlers.get(message.method)?.(message.params);
    }
  }
}
