/**
 * The facemime receiver page: decodes a facemime stream (docs/bitstream.md) and draws each frame
 * on the stream's actor with WebGL2. Served by ``facemime call``, it receives a live stream over
 * a WebSocket (``/stream``) and asks the sender for an intra packet when it joins and as soon as
 * it decodes a loss (again, at most every ``INTRA_EVERY_MS``, until it is back in sync);
 * anywhere, a saved ``.fmstream`` file dropped on it (or chosen) plays.
 *
 * For tests and measurements the page exposes ``window.facemime`` (see ``Api``). ``?drop=P``
 * drops each received packet with probability P (a seeded generator, ``&seed=N``), to test
 * concealment and resynchronisation; ``?slow=MS`` spends MS ms more on drawing each frame (a slow
 * machine), to test a page whose drawing lags behind the stream.
 */
import { readActor, type Actor, type Picture } from './render/actor';
import { applyUpdate, readUpdate, type Update } from './render/appearance';
import { Renderer } from './render/gl';
import { Synthesizer, type Motion } from './render/synth';
import { KIND_INTER, KIND_INTRA, StreamDecoder, type Event, type Frame, type Header } from './stream';

/** Seconds over which the frame rate and the received rate are averaged. */
const WINDOW_S = 5;
/** The least time between two intra requests, ms. */
const INTRA_EVERY_MS = 250;

interface Shown { index: number; face: boolean; concealed: boolean; lost: number; values: number[] }

/** What the page exposes as ``window.facemime``. */
interface Api {
  /** Every frame the decoder output, in order (decoded and concealed). */
  frames: Shown[];
  /** Counts and figures: the decoder's stats, frames drawn, frame rate, received kbit/s,
   * intra requests, packets dropped on purpose, the actor's set-up (ms, from its chunk to the
   * first frame it can draw), latencies ([frame index, ms] from a frame's arrival at the sender
   * to its picture drawn), draw times (ms). */
  stats(): Record<string, unknown>;
  /** Plays a saved stream's bytes (replacing what plays now); resolves once decoded. */
  loadStream(data: Uint8Array | string, autoplay?: boolean): Promise<void>;
  /** Draws frame ``index`` of the loaded stream (with the appearance updates due by then). */
  show(index: number): void;
  /** The canvas's pixels, RGBA rows from the top, base64. */
  pixels(): string;
  /** Draws ``count`` frames back to back; the mean ms per frame (GL finished). */
  benchmark(count: number): number;
  error: string | null;
}

const canvas = document.getElementById('picture') as HTMLCanvasElement;
const hud = document.getElementById('hud') as HTMLElement;
const message = document.getElementById('message') as HTMLElement;
const params = new URLSearchParams(location.search);
const dropShare = Number(params.get('drop') ?? 0);
const slowMs = Number(params.get('slow') ?? 0);
let seed = Number(params.get('seed') ?? 1) >>> 0 || 1;
const random = () => { // xorshift32: the same drops for the same seed
  seed ^= seed << 13; seed >>>= 0; seed ^= seed >>> 17; seed ^= seed << 5; seed >>>= 0;
  return seed / 2 ** 32;
};

const renderer = new Renderer(canvas);
const now = () => performance.timeOrigin + performance.now();

/** One stream being received or played: its decoder, actor, updates and frames. */
class Session {
  readonly decoder: StreamDecoder;
  header: Header | null = null;
  actor: Actor | null = null;
  texture: Picture | null = null;
  synth: Synthesizer | null = null;
  frames: Frame[] = [];
  /** Appearance updates with the number of frames output before each was read. */
  updates: { update: Update; after: number }[] = [];
  applied = 0;
  pending: Promise<void> = Promise.resolve();

  constructor(live: boolean) {
    this.decoder = new StreamDecoder(!live);
  }

  /** Takes the decoder's events in order (actor and images decode asynchronously, in turn). */
  take(events: Event[], onFrame: (f: Frame) => void): Promise<void> {
    for (const e of events) {
      this.pending = this.pending.then(async () => {
        if (e.kind === 'header') {
          if (this.header && this.actor && !same(this.header.actorId, e.header.actorId)) this.actor = null;
          this.header = e.header;
          this.synth = null;
          this.updates = [];
          this.applied = 0;
          this.frames = [];
          this.build();
        } else if (e.kind === 'actor') {
          if (!this.actor) {
            const t0 = performance.now();
            this.actor = await readActor(e.data);
            this.build();
            counts.setupMs = performance.now() - t0;
          }
        } else if (e.kind === 'appearance') {
          const update = await readUpdate(e.payload);
          if (update) this.updates.push({ update, after: this.frames.length });
          else api.counts.refused += 1;
        } else {
          await nextTask(); // the socket's messages are read between two drawings, not after all
          this.frames.push(e.frame);
          onFrame(e.frame);
        }
      });
    }
    return this.pending;
  }

  private build(): void {
    if (!this.header || !this.actor || this.synth) return;
    this.texture = { ...this.actor.texture, rgba: this.actor.texture.rgba.slice() };
    this.applied = 0;
    this.synth = new Synthesizer(renderer, this.actor, this.header);
    const [w, h] = [this.header.width, this.header.height];
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  }

  /** Draws ``frame`` (its updates applied first); false when the actor is not here yet. */
  draw(frame: Frame, position: number): boolean {
    if (!this.synth || !this.texture || !this.header) return false;
    let changed = false;
    // updates apply in stream order, each from its first frame, once read before this frame
    while (this.applied < this.updates.length) {
      const { update, after } = this.updates[this.applied];
      if (after > position || update.frame > frame.index) break;
      if (applyUpdate(this.texture, update)) changed = true; else api.counts.refused += 1;
      this.applied += 1;
    }
    if (changed) this.synth.retexture(this.texture);
    const [w, h] = this.synth.size;
    this.synth.draw(frame as Motion, letterbox(w, h, canvas.width, canvas.height));
    return true;
  }
}

/** Resolves in a task of its own, after the events already queued (a message from the socket
 * among them): drawing that lags behind the stream then delays no intra request. */
function nextTask(): Promise<void> {
  return new Promise((resolve) => {
    const channel = new MessageChannel();
    channel.port1.onmessage = () => resolve();
    channel.port2.postMessage(null);
  });
}

function same(a: Uint8Array, b: Uint8Array): boolean {
  return a.length === b.length && a.every((x, i) => x === b[i]);
}

/** [x, y, w, h] of a ``w`` x ``h`` picture fitted whole and centred into the canvas. */
function letterbox(w: number, h: number, cw: number, ch: number): number[] {
  const f = Math.min(cw / w, ch / h);
  const sw = Math.max(1, Math.round(w * f)), sh = Math.max(1, Math.round(h * f));
  return [Math.floor((cw - sw) / 2), Math.floor((ch - sh) / 2), sw, sh];
}

// --- the figures shown and exposed --------------------------------------------------------------
const counts = { drawn: 0, intraRequests: 0, dropped: 0, refused: 0, received: 0, setupMs: 0 };
const latencies: [number, number][] = []; // (frame index, ms)
const drawTimes: number[] = [];
const drawnAt: number[] = [];
const bytesAt: [number, number][] = [];
const arrived = new Map<number, number>();
let session: Session | null = null;
let lastRequest = -Infinity;
/** The live stream is out of sync (its last frame decoded was concealed): an intra packet is wanted. */
let outOfSync = false;
/** The pending check, ``INTRA_EVERY_MS`` after a request, of whether to ask again. */
let retry: ReturnType<typeof setTimeout> | null = null;
let socket: WebSocket | null = null;

function present(frame: Frame, position: number): void {
  if (!session) return;
  const t0 = performance.now();
  if (!session.draw(frame, position)) return;
  renderer.gl.finish();
  while (performance.now() - t0 < slowMs); // ?slow: a slower machine's drawing
  const t1 = performance.now();
  drawTimes.push(t1 - t0);
  counts.drawn += 1;
  drawnAt.push(t1);
  const sent = arrived.get(frame.index);
  if (sent !== undefined && !frame.concealed) latencies.push([frame.index, now() - sent]);
  arrived.delete(frame.index);
}

function updateHud(): void {
  const t = performance.now();
  while (drawnAt.length && drawnAt[0] < t - WINDOW_S * 1000) drawnAt.shift();
  while (bytesAt.length && bytesAt[0][0] < t - WINDOW_S * 1000) bytesAt.shift();
  const fps = drawnAt.length / WINDOW_S;
  const kbps = (bytesAt.reduce((s, [, b]) => s + b, 0) * 8) / 1000 / WINDOW_S;
  const s = session?.decoder.stats;
  const lat = latencies.length ? `, latency ${median(latencies.slice(-50).map((l) => l[1])).toFixed(0)} ms` : '';
  hud.textContent = `${fps.toFixed(1)} frames/s drawn · ${kbps.toFixed(2)} kbit/s received · `
    + `${s?.concealed ?? 0} frames concealed (${s?.lost_packets ?? 0} packets lost)${lat}`;
}

function median(xs: number[]): number {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? s[Math.floor(s.length / 2)] : NaN;
}

function fail(text: string): void {
  api.error = text;
  message.textContent = text;
  message.hidden = false;
}

// --- live: a WebSocket from facemime call ----------------------------------------------------------
/** Asks the sender for an intra packet (at most every ``INTRA_EVERY_MS``), and again every
 * ``INTRA_EVERY_MS`` while the stream stays out of sync: a request, or the intra packet answering
 * it, can be lost, and packets can come in a burst after a stall and then none (a request only
 * on a packet's arrival would leave the page concealing to the end). */
function requestIntra(): void {
  if (!socket || socket.readyState !== WebSocket.OPEN || retry !== null) return;
  const wait = lastRequest + INTRA_EVERY_MS - performance.now();
  if (wait <= 0) {
    lastRequest = performance.now();
    counts.intraRequests += 1;
    socket.send(JSON.stringify({ type: 'intra' }));
  }
  retry = setTimeout(() => { retry = null; if (outOfSync) requestIntra(); }, wait > 0 ? wait : INTRA_EVERY_MS);
}

function connect(): void {
  const live = new Session(true);
  session = live;
  outOfSync = false;
  const ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/stream`);
  ws.binaryType = 'arraybuffer';
  socket = ws;
  ws.onopen = () => { message.hidden = true; requestIntra(); };
  ws.onmessage = (m) => {
    if (typeof m.data === 'string') {
      const note = JSON.parse(m.data);
      if (note.type === 'frames') note.arrived.forEach((t: number, j: number) => arrived.set(note.first + j, t));
      if (note.type === 'end') message.textContent = 'the call has ended';
      if (note.type === 'end') message.hidden = false;
      return;
    }
    const bytes = new Uint8Array(m.data as ArrayBuffer);
    const kind = bytes[0] >> 5;
    if (kind === KIND_INTRA || kind === KIND_INTER) {
      if (dropShare > 0 && random() < dropShare) { counts.dropped += 1; return; }
      counts.received += bytes.length;
      bytesAt.push([performance.now(), bytes.length]);
    }
    const events = live.decoder.push(bytes);
    // asked now, as decoded, not when drawn: drawing can lag behind the stream
    for (const e of events) if (e.kind === 'frame') outOfSync = e.frame.concealed;
    if (outOfSync) requestIntra();
    live.take(events, (f) => {
      api.frames.push(shown(f));
      present(f, live.frames.length - 1);
    }).catch((e) => fail(`cannot play the call: ${(e as Error).message}`));
  };
  ws.onclose = (e) => {
    socket = null;
    if (session === live && e.code !== 1000) {
      message.textContent = 'the sender is gone: reconnecting…';
      message.hidden = false;
      setTimeout(connect, 1000);
    }
  };
}

function shown(f: Frame): Shown {
  return { index: f.index, face: f.face, concealed: f.concealed, lost: f.lost, values: Array.from(f.values) };
}

// --- a saved stream -----------------------------------------------------------------------------
let playing = 0;

async function loadStream(data: Uint8Array | string, autoplay = true): Promise<void> {
  const bytes = typeof data === 'string' ? Uint8Array.from(atob(data), (c) => c.charCodeAt(0)) : data;
  socket?.close(1000);
  const file = new Session(false);
  session = file;
  api.frames = [];
  const collect = (f: Frame) => { api.frames.push(shown(f)); };
  await file.take(file.decoder.push(bytes), collect);
  await file.take(file.decoder.finish(), collect);
  if (!file.header) throw new Error('this is not a facemime stream (no header found)');
  if (!file.synth) throw new Error('the stream does not carry its actor');
  message.hidden = true;
  const run = ++playing;
  if (!autoplay) return;
  const fps = file.header.fps[0] / file.header.fps[1];
  const start = performance.now();
  const tick = () => {
    if (run !== playing || session !== file) return;
    const i = Math.floor(((performance.now() - start) / 1000) * fps) % file.frames.length;
    present(file.frames[i], i);
    updateHud();
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}

const api: Api & { counts: typeof counts } = {
  frames: [],
  counts,
  error: null,
  stats: () => ({
    ...(session?.decoder.stats ?? {}), ...counts, latencies: [...latencies], drawTimes: [...drawTimes],
    header: session?.header ? { width: session.header.width, height: session.header.height, fps: session.header.fps } : null,
  }),
  loadStream: (data, autoplay = true) => loadStream(data, autoplay),
  show: (index) => {
    if (!session) throw new Error('no stream loaded');
    playing += 1; // stops a playback
    const position = session.frames.findIndex((f) => f.index === index);
    if (position < 0) throw new Error(`no frame ${index}`);
    session.texture = session.actor ? { ...session.actor.texture, rgba: session.actor.texture.rgba.slice() } : null;
    session.applied = 0;
    if (session.texture) session.synth?.retexture(session.texture);
    present(session.frames[position], position);
  },
  pixels: () => {
    const p = renderer.pixels();
    let s = '';
    for (let i = 0; i < p.length; i += 0x8000) s += String.fromCharCode(...p.subarray(i, i + 0x8000));
    return btoa(s);
  },
  benchmark: (count) => {
    if (!session?.synth) throw new Error('no stream loaded');
    playing += 1;
    const t0 = performance.now();
    for (let i = 0; i < count; i++) {
      const f = session.frames[i % session.frames.length];
      session.synth.draw(f as Motion, [0, 0, canvas.width, canvas.height]);
      renderer.gl.finish();
    }
    return (performance.now() - t0) / count;
  },
};
(window as unknown as { facemime: typeof api }).facemime = api;

// --- the page -----------------------------------------------------------------------------------
const chooser = document.getElementById('file') as HTMLInputElement;
const play = (f: File) => f.arrayBuffer().then((b) => loadStream(new Uint8Array(b)))
  .catch((e) => fail(`cannot play ${f.name}: ${(e as Error).message}`));
chooser.onchange = () => { if (chooser.files?.[0]) void play(chooser.files[0]); };
document.body.ondragover = (e) => e.preventDefault();
document.body.ondrop = (e) => {
  e.preventDefault();
  const f = e.dataTransfer?.files[0];
  if (f) void play(f);
};
setInterval(updateHud, 500);
if (location.protocol.startsWith('http') && params.get('live') !== '0') connect();
else { message.textContent = 'drop a .fmstream file here, or choose one'; message.hidden = false; }
