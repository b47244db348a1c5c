/**
 * WebGL2 drawing of a synthesised frame, in the Python renderer's order
 * (facemime.animate.synth.synthesize): the scene warped (or a plain background), the mouth
 * interior blended in, then the face mesh, back-facing triangles culled and the rest drawn far
 * to near by mean depth (the painter's algorithm of facemime.render.raster), sampled
 * bilinearly.
 *
 * Positions come in image pixels (x right, y down, (0, 0) the centre of the top-left pixel);
 * texture coordinates in [0, 1] from the texture's top-left corner, so texel centres sit where
 * the Python renderer puts them.
 */
import type { Picture } from './actor';
import type { MouthPatch } from './mouth';

const VERTEX = `#version 300 es
in vec2 position;
in vec2 uv;
uniform vec2 size;
out vec2 v_uv;
void main() {
  vec2 c = (position + 0.5) / size * 2.0 - 1.0;
  gl_Position = vec4(c.x, -c.y, 0.0, 1.0);
  v_uv = uv;
}`;
const FRAGMENT = `#version 300 es
precision highp float;
in vec2 v_uv;
uniform sampler2D image;
uniform vec4 tint;
out vec4 colour;
void main() {
  colour = tint.a < 0.0 ? texture(image, v_uv) : tint;
}`;

export interface Layer { texture: WebGLTexture; width: number; height: number }

export class Renderer {
  readonly gl: WebGL2RenderingContext;
  private readonly program: WebGLProgram;
  private readonly positions: WebGLBuffer;
  private readonly uvs: WebGLBuffer;
  private readonly indices: WebGLBuffer;
  private readonly nearest: WebGLSampler;
  private readonly linear: WebGLSampler;
  private readonly mouth: WebGLTexture;
  private readonly loc: { position: number; uv: number; size: WebGLUniformLocation; tint: WebGLUniformLocation };

  constructor(readonly canvas: HTMLCanvasElement) {
    const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true, premultipliedAlpha: false, alpha: false });
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    const shader = (type: number, text: string) => {
      const s = gl.createShader(type) as WebGLShader;
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s) ?? 'shader');
      return s;
    };
    const p = gl.createProgram() as WebGLProgram;
    gl.attachShader(p, shader(gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p) ?? 'program');
    this.program = p;
    this.loc = {
      position: gl.getAttribLocation(p, 'position'), uv: gl.getAttribLocation(p, 'uv'),
      size: gl.getUniformLocation(p, 'size') as WebGLUniformLocation,
      tint: gl.getUniformLocation(p, 'tint') as WebGLUniformLocation,
    };
    this.positions = gl.createBuffer() as WebGLBuffer;
    this.uvs = gl.createBuffer() as WebGLBuffer;
    this.indices = gl.createBuffer() as WebGLBuffer;
    const sampler = (filter: number) => {
      const s = gl.createSampler() as WebGLSampler;
      gl.samplerParameteri(s, gl.TEXTURE_MIN_FILTER, filter);
      gl.samplerParameteri(s, gl.TEXTURE_MAG_FILTER, filter);
      gl.samplerParameteri(s, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.samplerParameteri(s, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
      return s;
    };
    this.nearest = sampler(gl.NEAREST);
    this.linear = sampler(gl.LINEAR);
    this.mouth = gl.createTexture() as WebGLTexture;
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.pixelStorei(gl.PACK_ALIGNMENT, 1);
  }

  /** A texture of ``picture`` (replaced in place when ``into`` is given). */
  upload(picture: Picture, into?: Layer): Layer {
    const gl = this.gl;
    const texture = into?.texture ?? (gl.createTexture() as WebGLTexture);
    gl.bindTexture(gl.TEXTURE_2D, texture);
    if (into && into.width === picture.width && into.height === picture.height) {
      gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, picture.width, picture.height, gl.RGBA, gl.UNSIGNED_BYTE, picture.rgba);
    } else {
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, picture.width, picture.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, picture.rgba);
    }
    return { texture, width: picture.width, height: picture.height };
  }

  /** Starts a picture of ``width`` x ``height`` px drawn into the viewport rectangle ``view``
   * ([x, y, w, h] of the canvas, y from the top), cleared to ``background`` (RGB 0-255). */
  begin(width: number, height: number, background: readonly number[], view = [0, 0, width, height]): void {
    const gl = this.gl;
    gl.viewport(view[0], this.canvas.height - view[1] - view[3], view[2], view[3]);
    gl.disable(gl.SCISSOR_TEST);
    gl.clearColor(background[0] / 255, background[1] / 255, background[2] / 255, 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
    gl.useProgram(this.program);
    gl.uniform2f(this.loc.size, width, height);
  }

  /** Draws ``triangles`` (vertex index triples) of a mesh at ``points`` (px) textured by
   * ``layer`` at ``uv``, sampled nearest or bilinear; with ``cull``, triangles that run clockwise
   * in the image (back-facing) are skipped. */
  mesh(layer: Layer, points: ArrayLike<number>, uv: ArrayLike<number>, triangles: Uint32Array, bilinear: boolean,
    cull: boolean): void {
    if (triangles.length === 0) return;
    const gl = this.gl;
    this.attributes(points, uv);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, layer.texture);
    gl.bindSampler(0, bilinear ? this.linear : this.nearest);
    gl.uniform4f(this.loc.tint, 0, 0, 0, -1);
    gl.disable(gl.BLEND);
    if (cull) {
      gl.enable(gl.CULL_FACE);
      gl.frontFace(gl.CW); // counter-clockwise with y down is clockwise once y points up
      gl.cullFace(gl.BACK);
    } else {
      gl.disable(gl.CULL_FACE);
    }
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, triangles, gl.STREAM_DRAW);
    gl.drawElements(gl.TRIANGLES, triangles.length, gl.UNSIGNED_INT, 0);
  }

  /** Blends the mouth interior ``patch`` in (its alpha the opening). */
  mouthPatch(patch: MouthPatch): void {
    const gl = this.gl;
    gl.bindTexture(gl.TEXTURE_2D, this.mouth);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, patch.width, patch.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, patch.rgba);
    const x0 = patch.x0 - 0.5, y0 = patch.y0 - 0.5, x1 = x0 + patch.width, y1 = y0 + patch.height;
    this.quad([x0, y0, x1, y0, x1, y1, x0, y1], { texture: this.mouth, width: patch.width, height: patch.height });
  }

  /** Darkens the whole picture to ``factor`` of its brightness (a frame without a face). */
  dim(factor: number, width: number, height: number): void {
    this.quad([-0.5, -0.5, width - 0.5, -0.5, width - 0.5, height - 0.5, -0.5, height - 0.5], null, [0, 0, 0, 1 - factor]);
  }

  private quad(corners: number[], layer: Layer | null, tint = [0, 0, 0, -1]): void {
    const gl = this.gl;
    this.attributes(corners, [0, 0, 1, 0, 1, 1, 0, 1]);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, layer ? layer.texture : null);
    gl.bindSampler(0, this.nearest);
    gl.uniform4f(this.loc.tint, tint[0], tint[1], tint[2], tint[3]);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
    gl.disable(gl.CULL_FACE);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indices);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array([0, 1, 2, 0, 2, 3]), gl.STREAM_DRAW);
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_INT, 0);
    gl.disable(gl.BLEND);
  }

  private attributes(points: ArrayLike<number>, uv: ArrayLike<number>): void {
    const gl = this.gl;
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positions);
    gl.bufferData(gl.ARRAY_BUFFER, Float32Array.from(points), gl.STREAM_DRAW);
    gl.enableVertexAttribArray(this.loc.position);
    gl.vertexAttribPointer(this.loc.position, 2, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.uvs);
    gl.bufferData(gl.ARRAY_BUFFER, Float32Array.from(uv), gl.STREAM_DRAW);
    gl.enableVertexAttribArray(this.loc.uv);
    gl.vertexAttribPointer(this.loc.uv, 2, gl.FLOAT, false, 0, 0);
  }

  /** The canvas's pixels, RGBA row-major from the top-left. */
  pixels(): Uint8Array {
    const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
    const raw = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, raw);
    const out = new Uint8Array(raw.length);
    for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
    return out;
  }
}
