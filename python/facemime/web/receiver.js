"use strict";
(() => {
  // node_modules/fflate/esm/browser.js
  var u8 = Uint8Array;
  var u16 = Uint16Array;
  var i32 = Int32Array;
  var fleb = new u8([
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    1,
    1,
    1,
    1,
    2,
    2,
    2,
    2,
    3,
    3,
    3,
    3,
    4,
    4,
    4,
    4,
    5,
    5,
    5,
    5,
    0,
    /* unused */
    0,
    0,
    /* impossible */
    0
  ]);
  var fdeb = new u8([
    0,
    0,
    0,
    0,
    1,
    1,
    2,
    2,
    3,
    3,
    4,
    4,
    5,
    5,
    6,
    6,
    7,
    7,
    8,
    8,
    9,
    9,
    10,
    10,
    11,
    11,
    12,
    12,
    13,
    13,
    /* unused */
    0,
    0
  ]);
  var clim = new u8([16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15]);
  var freb = function(eb2, start) {
    var b = new u16(31);
    for (var i2 = 0; i2 < 31; ++i2) {
      b[i2] = start += 1 << eb2[i2 - 1];
    }
    var r = new i32(b[30]);
    for (var i2 = 1; i2 < 30; ++i2) {
      for (var j = b[i2]; j < b[i2 + 1]; ++j) {
        r[j] = j - b[i2] << 5 | i2;
      }
    }
    return { b, r };
  };
  var _a = freb(fleb, 2);
  var fl = _a.b;
  var revfl = _a.r;
  fl[28] = 258, revfl[258] = 28;
  var _b = freb(fdeb, 0);
  var fd = _b.b;
  var revfd = _b.r;
  var rev = new u16(32768);
  for (i = 0; i < 32768; ++i) {
    x = (i & 43690) >> 1 | (i & 21845) << 1;
    x = (x & 52428) >> 2 | (x & 13107) << 2;
    x = (x & 61680) >> 4 | (x & 3855) << 4;
    rev[i] = ((x & 65280) >> 8 | (x & 255) << 8) >> 1;
  }
  var x;
  var i;
  var hMap = (function(cd2, mb, r) {
    var s = cd2.length;
    var i2 = 0;
    var l = new u16(mb);
    for (; i2 < s; ++i2) {
      if (cd2[i2])
        ++l[cd2[i2] - 1];
    }
    var le = new u16(mb);
    for (i2 = 1; i2 < mb; ++i2) {
      le[i2] = le[i2 - 1] + l[i2 - 1] << 1;
    }
    var co;
    if (r) {
      co = new u16(1 << mb);
      var rvb = 15 - mb;
      for (i2 = 0; i2 < s; ++i2) {
        if (cd2[i2]) {
          var sv = i2 << 4 | cd2[i2];
          var r_1 = mb - cd2[i2];
          var v2 = le[cd2[i2] - 1]++ << r_1;
          for (var m = v2 | (1 << r_1) - 1; v2 <= m; ++v2) {
            co[rev[v2] >> rvb] = sv;
          }
        }
      }
    } else {
      co = new u16(s);
      for (i2 = 0; i2 < s; ++i2) {
        if (cd2[i2]) {
          co[i2] = rev[le[cd2[i2] - 1]++] >> 15 - cd2[i2];
        }
      }
    }
    return co;
  });
  var flt = new u8(288);
  for (i = 0; i < 144; ++i)
    flt[i] = 8;
  var i;
  for (i = 144; i < 256; ++i)
    flt[i] = 9;
  var i;
  for (i = 256; i < 280; ++i)
    flt[i] = 7;
  var i;
  for (i = 280; i < 288; ++i)
    flt[i] = 8;
  var i;
  var fdt = new u8(32);
  for (i = 0; i < 32; ++i)
    fdt[i] = 5;
  var i;
  var flrm = /* @__PURE__ */ hMap(flt, 9, 1);
  var fdrm = /* @__PURE__ */ hMap(fdt, 5, 1);
  var max = function(a) {
    var m = a[0];
    for (var i2 = 1; i2 < a.length; ++i2) {
      if (a[i2] > m)
        m = a[i2];
    }
    return m;
  };
  var bits = function(d, p, m) {
    var o = p / 8 | 0;
    return (d[o] | d[o + 1] << 8) >> (p & 7) & m;
  };
  var bits16 = function(d, p) {
    var o = p / 8 | 0;
    return (d[o] | d[o + 1] << 8 | d[o + 2] << 16) >> (p & 7);
  };
  var shft = function(p) {
    return (p + 7) / 8 | 0;
  };
  var slc = function(v2, s, e) {
    if (s == null || s < 0)
      s = 0;
    if (e == null || e > v2.length)
      e = v2.length;
    return new u8(v2.subarray(s, e));
  };
  var ec = [
    "unexpected EOF",
    "invalid block type",
    "invalid length/literal",
    "invalid distance",
    "stream finished",
    "no stream handler",
    ,
    // determined by compression function
    "no callback",
    "invalid UTF-8 data",
    "extra field too long",
    "date not in range 1980-2099",
    "filename too long",
    "stream finishing",
    "invalid zip data"
    // determined by unknown compression method
  ];
  var err = function(ind, msg, nt) {
    var e = new Error(msg || ec[ind]);
    e.code = ind;
    if (Error.captureStackTrace)
      Error.captureStackTrace(e, err);
    if (!nt)
      throw e;
    return e;
  };
  var inflt = function(dat, st, buf, dict) {
    var sl = dat.length, dl = dict ? dict.length : 0;
    if (!sl || st.f && !st.l)
      return buf || new u8(0);
    var noBuf = !buf;
    var resize = noBuf || st.i != 2;
    var noSt = st.i;
    if (noBuf)
      buf = new u8(sl * 3);
    var cbuf = function(l2) {
      var bl = buf.length;
      if (l2 > bl) {
        var nbuf = new u8(Math.max(bl * 2, l2));
        nbuf.set(buf);
        buf = nbuf;
      }
    };
    var final = st.f || 0, pos = st.p || 0, bt = st.b || 0, lm = st.l, dm = st.d, lbt = st.m, dbt = st.n;
    var tbts = sl * 8;
    do {
      if (!lm) {
        final = bits(dat, pos, 1);
        var type = bits(dat, pos + 1, 3);
        pos += 3;
        if (!type) {
          var s = shft(pos) + 4, l = dat[s - 4] | dat[s - 3] << 8, t = s + l;
          if (t > sl) {
            if (noSt)
              err(0);
            break;
          }
          if (resize)
            cbuf(bt + l);
          buf.set(dat.subarray(s, t), bt);
          st.b = bt += l, st.p = pos = t * 8, st.f = final;
          continue;
        } else if (type == 1)
          lm = flrm, dm = fdrm, lbt = 9, dbt = 5;
        else if (type == 2) {
          var hLit = bits(dat, pos, 31) + 257, hcLen = bits(dat, pos + 10, 15) + 4;
          var tl = hLit + bits(dat, pos + 5, 31) + 1;
          pos += 14;
          var ldt = new u8(tl);
          var clt = new u8(19);
          for (var i2 = 0; i2 < hcLen; ++i2) {
            clt[clim[i2]] = bits(dat, pos + i2 * 3, 7);
          }
          pos += hcLen * 3;
          var clb = max(clt), clbmsk = (1 << clb) - 1;
          var clm = hMap(clt, clb, 1);
          for (var i2 = 0; i2 < tl; ) {
            var r = clm[bits(dat, pos, clbmsk)];
            pos += r & 15;
            var s = r >> 4;
            if (s < 16) {
              ldt[i2++] = s;
            } else {
              var c = 0, n = 0;
              if (s == 16)
                n = 3 + bits(dat, pos, 3), pos += 2, c = ldt[i2 - 1];
              else if (s == 17)
                n = 3 + bits(dat, pos, 7), pos += 3;
              else if (s == 18)
                n = 11 + bits(dat, pos, 127), pos += 7;
              while (n--)
                ldt[i2++] = c;
            }
          }
          var lt = ldt.subarray(0, hLit), dt = ldt.subarray(hLit);
          lbt = max(lt);
          dbt = max(dt);
          lm = hMap(lt, lbt, 1);
          dm = hMap(dt, dbt, 1);
        } else
          err(1);
        if (pos > tbts) {
          if (noSt)
            err(0);
          break;
        }
      }
      if (resize)
        cbuf(bt + 131072);
      var lms = (1 << lbt) - 1, dms = (1 << dbt) - 1;
      var lpos = pos;
      for (; ; lpos = pos) {
        var c = lm[bits16(dat, pos) & lms], sym = c >> 4;
        pos += c & 15;
        if (pos > tbts) {
          if (noSt)
            err(0);
          break;
        }
        if (!c)
          err(2);
        if (sym < 256)
          buf[bt++] = sym;
        else if (sym == 256) {
          lpos = pos, lm = null;
          break;
        } else {
          var add = sym - 254;
          if (sym > 264) {
            var i2 = sym - 257, b = fleb[i2];
            add = bits(dat, pos, (1 << b) - 1) + fl[i2];
            pos += b;
          }
          var d = dm[bits16(dat, pos) & dms], dsym = d >> 4;
          if (!d)
            err(3);
          pos += d & 15;
          var dt = fd[dsym];
          if (dsym > 3) {
            var b = fdeb[dsym];
            dt += bits16(dat, pos) & (1 << b) - 1, pos += b;
          }
          if (pos > tbts) {
            if (noSt)
              err(0);
            break;
          }
          if (resize)
            cbuf(bt + 131072);
          var end = bt + add;
          if (bt < dt) {
            var shift = dl - dt, dend = Math.min(dt, end);
            if (shift + bt < 0)
              err(3);
            for (; bt < dend; ++bt)
              buf[bt] = dict[shift + bt];
          }
          for (; bt < end; ++bt)
            buf[bt] = buf[bt - dt];
        }
      }
      st.l = lm, st.p = lpos, st.b = bt, st.f = final;
      if (lm)
        final = 1, st.m = lbt, st.d = dm, st.n = dbt;
    } while (!final);
    return bt != buf.length && noBuf ? slc(buf, 0, bt) : buf.subarray(0, bt);
  };
  var et = /* @__PURE__ */ new u8(0);
  var b2 = function(d, b) {
    return d[b] | d[b + 1] << 8;
  };
  var b4 = function(d, b) {
    return (d[b] | d[b + 1] << 8 | d[b + 2] << 16 | d[b + 3] << 24) >>> 0;
  };
  var b8 = function(d, b) {
    return b4(d, b) + b4(d, b + 4) * 4294967296;
  };
  function inflateSync(data, opts) {
    return inflt(data, { i: 2 }, opts && opts.out, opts && opts.dictionary);
  }
  var td = typeof TextDecoder != "undefined" && /* @__PURE__ */ new TextDecoder();
  var tds = 0;
  try {
    td.decode(et, { stream: true });
    tds = 1;
  } catch (e) {
  }
  var dutf8 = function(d) {
    for (var r = "", i2 = 0; ; ) {
      var c = d[i2++];
      var eb2 = (c > 127) + (c > 223) + (c > 239);
      if (i2 + eb2 > d.length)
        return { s: r, r: slc(d, i2 - 1) };
      if (!eb2)
        r += String.fromCharCode(c);
      else if (eb2 == 3) {
        c = ((c & 15) << 18 | (d[i2++] & 63) << 12 | (d[i2++] & 63) << 6 | d[i2++] & 63) - 65536, r += String.fromCharCode(55296 | c >> 10, 56320 | c & 1023);
      } else if (eb2 & 1)
        r += String.fromCharCode((c & 31) << 6 | d[i2++] & 63);
      else
        r += String.fromCharCode((c & 15) << 12 | (d[i2++] & 63) << 6 | d[i2++] & 63);
    }
  };
  function strFromU8(dat, latin1) {
    if (latin1) {
      var r = "";
      for (var i2 = 0; i2 < dat.length; i2 += 16384)
        r += String.fromCharCode.apply(null, dat.subarray(i2, i2 + 16384));
      return r;
    } else if (td) {
      return td.decode(dat);
    } else {
      var _a2 = dutf8(dat), s = _a2.s, r = _a2.r;
      if (r.length)
        err(8);
      return s;
    }
  }
  var slzh = function(d, b) {
    return b + 30 + b2(d, b + 26) + b2(d, b + 28);
  };
  var zh = function(d, b, z) {
    var fnl = b2(d, b + 28), efl = b2(d, b + 30), fn = strFromU8(d.subarray(b + 46, b + 46 + fnl), !(b2(d, b + 8) & 2048)), es = b + 46 + fnl;
    var _a2 = z64hs(d, es, efl, z, b4(d, b + 20), b4(d, b + 24), b4(d, b + 42)), sc = _a2[0], su = _a2[1], off = _a2[2];
    return [b2(d, b + 10), sc, su, fn, es + efl + b2(d, b + 32), off];
  };
  var z64hs = function(d, b, l, z, sc, su, off) {
    var nsc = sc == 4294967295, nsu = su == 4294967295, noff = off == 4294967295, e = b + l;
    var nf = nsc + nsu + noff;
    if (z && nf) {
      for (; b + 4 < e; b += 4 + b2(d, b + 2)) {
        if (b2(d, b) == 1) {
          return [
            nsc ? b8(d, b + 4 + 8 * nsu) : sc,
            nsu ? b8(d, b + 4) : su,
            noff ? b8(d, b + 4 + 8 * (nsu + nsc)) : off,
            1
          ];
        }
      }
      if (z < 2)
        err(13);
    }
    return [sc, su, off, 0];
  };
  function unzipSync(data, opts) {
    var files = {};
    var e = data.length - 22;
    for (; b4(data, e) != 101010256; --e) {
      if (!e || data.length - e > 65558)
        err(13);
    }
    ;
    var c = b2(data, e + 8);
    if (!c)
      return {};
    var o = b4(data, e + 16);
    var z = b4(data, e - 20) == 117853008;
    if (z) {
      var ze = b4(data, e - 12);
      z = b4(data, ze) == 101075792;
      if (z) {
        c = b4(data, ze + 32);
        o = b4(data, ze + 48);
      }
    }
    var fltr = opts && opts.filter;
    for (var i2 = 0; i2 < c; ++i2) {
      var _a2 = zh(data, o, z), c_2 = _a2[0], sc = _a2[1], su = _a2[2], fn = _a2[3], no = _a2[4], off = _a2[5], b = slzh(data, off);
      o = no;
      if (!fltr || fltr({
        name: fn,
        size: sc,
        originalSize: su,
        compression: c_2
      })) {
        if (!c_2)
          files[fn] = slc(data, b, b + sc);
        else if (c_2 == 8)
          files[fn] = inflateSync(data.subarray(b, b + sc), { out: new u8(su) });
        else
          err(14, "unknown compression type " + c_2);
      }
    }
    return files;
  }

  // src/shared_constants.ts
  var POSE_FIELDS = ["yaw", "pitch", "roll", "scale", "tx", "ty"];
  var LOOK_NAMES = [
    "eye_right_closure",
    "eye_left_closure",
    "iris_right_u",
    "iris_right_v",
    "iris_left_u",
    "iris_left_v"
  ];
  var BASIS_ONE = 32767;
  var SAMPLE_KINDS = [7, 8];
  var CONTOUR_GROUPS = [
    "mouth_outer_upper",
    "mouth_outer_lower",
    "mouth_inner_upper",
    "mouth_inner_lower",
    "brow_left_upper",
    "brow_left_lower",
    "brow_right_upper",
    "brow_right_lower"
  ];
  var SOFTEN = 0.02;
  var REACH = 0.45;
  var SEAL = 0.05;
  var SAMPLE_GROUPS = ["eyes", "mouth"];
  var INTERIOR_SIZE = [96, 40];
  var IRIS_WEIGHT = 5;
  var BACKGROUND = [38, 40, 46];
  var NO_FACE_DIM = 0.45;
  var CAVITY = [52, 18, 22];
  var TEETH = [185, 165, 150];
  var GAPS = [150, 140, 128];
  var UPPER_TEETH = 0.11;
  var LOWER_TEETH = 0.07;
  var TEETH_SPAN = 0.72;
  var UPPER_SHARE = 0.6;
  var LOWER_SHARE = 0.4;
  var TEETH_FROM = 0.04;
  var TEETH_SPREAD = [0.9, 1.05];
  var UPPER_MIN = 0.5;
  var SHIFT = 4;
  var EYES = ["eye_right", "eye_left"];
  var DENSITY = 20;
  var SPAN_U = [-0.7, 0.7];
  var SPAN_V = [-0.55, 0.55];
  var IRIS_RADIUS = 0.21;
  var LID_EDGE = 0.04;
  var IRIS_U = 0.32;
  var IRIS_V = [-0.2, 0.2];
  var UPPER_LID = [1, 2, 3];
  var LOWER_LID = [7, 6, 5];
  var PASTE_STILL = 0.25;
  var IRIS_REACH = 1.15;
  var RINGS = [[1.2, 1], [1.7, 0]];
  var EDGE_MARGIN = 0.04;
  var BORDER_STEPS = 9;
  var SLOW = 1;

  // src/render/actor.ts
  var MAX_SAMPLES = 64;
  var MAX_BOXES = 4;
  var MAX_KEY = 1e4;
  var MAX_TEXELS = 1 << 24;
  var MAX_MEMBER = 64 << 20;
  async function decodeImage(bytes, type) {
    const bitmap = await createImageBitmap(
      new Blob([bytes], { type }),
      { colorSpaceConversion: "none", premultiplyAlpha: "none" }
    );
    const canvas2 = document.createElement("canvas");
    canvas2.width = bitmap.width;
    canvas2.height = bitmap.height;
    const ctx = canvas2.getContext("2d", { willReadFrequently: true });
    ctx.drawImage(bitmap, 0, 0);
    const data = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
    bitmap.close();
    return { width: canvas2.width, height: canvas2.height, rgba: new Uint8Array(data.buffer) };
  }
  var numbers = (a, what) => {
    const flat = a.flat(2);
    if (!Array.isArray(a) || flat.some((x2) => typeof x2 !== "number" || !Number.isFinite(x2))) {
      throw new Error(`the actor's ${what} are malformed`);
    }
    return flat;
  };
  async function readActor(data) {
    let files;
    try {
      files = unzipSync(data, { filter: (f) => f.originalSize <= MAX_MEMBER });
    } catch (e) {
      throw new Error(`the actor is not a facemime actor file (${e.message})`);
    }
    const text = files["actor.json"];
    if (!text) throw new Error("the actor has no actor.json");
    const doc = JSON.parse(new TextDecoder().decode(text));
    if (doc?.format !== "facemime.actor/1") throw new Error(`the actor's format is ${JSON.stringify(doc?.format)}`);
    const m = doc.model;
    const vertices = Float64Array.from(numbers(m.vertices, "vertices"));
    const model = {
      vertices,
      triangles: Uint32Array.from(numbers(m.triangles, "triangles")),
      uv: Float64Array.from(numbers(m.uv, "texture coordinates")),
      groups: m.groups
    };
    const n = vertices.length / 3;
    if (model.uv.length !== 2 * n || model.triangles.some((i2) => i2 >= n)) throw new Error("the actor's model is inconsistent");
    const picture = async (stem) => {
      for (const [ext, type] of [["webp", "image/webp"], ["png", "image/png"]]) {
        const bytes = files[`${stem}.${ext}`];
        if (bytes) return decodeImage(bytes, type);
      }
      return null;
    };
    const texture = await picture("texture");
    if (!texture) throw new Error("the actor has no texture");
    const scene = doc.scene ? await picture("scene") : null;
    const samples = files["samples.json"] ? await readSamples(files, texture, model) : null;
    return { model, pose: doc.pose, source: doc.source, texture, scene, samples };
  }
  async function readSamples(files, texture, model) {
    const bad = (why) => {
      throw new Error(`the actor's samples.json is malformed (${why})`);
    };
    let doc;
    try {
      doc = JSON.parse(new TextDecoder().decode(files["samples.json"]));
    } catch (e) {
      return bad(e.message);
    }
    if (doc?.format !== "facemime.samples/1" || !Array.isArray(doc.groups)) bad("not a facemime.samples/1 document");
    const groups = [];
    for (const g of doc.groups) {
      const { name, boxes, samples } = g ?? {};
      if (!SAMPLE_GROUPS.includes(name)) bad(`a group is one of ${SAMPLE_GROUPS.join(", ")}, got ${JSON.stringify(name)}`);
      if (groups.some((h) => h.name === name)) bad(`group ${name} appears twice`);
      if (!Array.isArray(boxes) || boxes.length < 1 || boxes.length > MAX_BOXES || boxes.some((b) => !Array.isArray(b) || b.length !== 4 || b.some((v2) => !Number.isInteger(v2) || v2 < 0) || b[2] < 1 || b[3] < 1 || b[0] + b[2] > texture.width || b[1] + b[3] > texture.height)) {
        bad(`group ${name}: boxes must be 1-${MAX_BOXES} rows of x, y, width, height inside the texture`);
      }
      if (!Array.isArray(samples) || samples.length < 1 || samples.length > MAX_SAMPLES) bad(`group ${name}: a group holds 1-${MAX_SAMPLES} samples`);
      const entries = samples;
      const keys = entries.map((e) => {
        const key = e?.key;
        if (!Array.isArray(key) || key.some((v2) => typeof v2 !== "number" || !Number.isFinite(v2) || Math.abs(v2) > MAX_KEY)) return bad(`group ${name}: a sample's key is not a list of finite numbers within ±${MAX_KEY}`);
        return Float64Array.from(key);
      });
      const lips = new Set(["mouth_outer_upper", "mouth_outer_lower", "mouth_inner_upper", "mouth_inner_lower"].flatMap((g2) => [...model.groups[g2]])).size;
      if (keys.some((k) => k.length !== (name === "eyes" ? 6 : 2 * lips))) bad(`group ${name}: keys of the wrong length`);
      const rectsAll = boxes;
      if (entries.length * rectsAll.reduce((t, [, , w, h]) => t + w * h, 0) > MAX_TEXELS) bad(`group ${name}: more than ${MAX_TEXELS} texels of images`);
      if (entries.some((e) => e?.interior !== void 0 && typeof e.interior !== "boolean")) bad(`group ${name}: a sample's interior is true or false`);
      const frames = entries.map((e) => Number.isInteger(e?.frame) ? e.frame : bad(`group ${name}: a sample's frame is not an integer`));
      const rects = boxes;
      const inside = entries.map((e) => e?.interior === true);
      const atlas = async (b, count) => {
        for (const [ext, type] of [["png", "image/png"], ["webp", "image/webp"]]) {
          const member = `samples/${name}/${b}.${ext}`;
          const bytes = files[member];
          if (!bytes) continue;
          let whole;
          try {
            whole = await decodeImage(bytes, type);
          } catch {
            return bad(`sample image ${member} does not decode`);
          }
          if (whole.height % count) bad(`sample image ${member} does not hold ${count} images of one height`);
          const h = whole.height / count, row = 4 * whole.width;
          return Array.from({ length: count }, (_, k) => ({
            width: whole.width,
            height: h,
            rgba: whole.rgba.slice(k * h * row, (k + 1) * h * row)
          }));
        }
        return bad(`group ${name} has no image of ${b === "interior" ? "its interiors" : `box ${b}`}`);
      };
      const perBox = await Promise.all(rects.map(async ([, , w, h], b) => {
        const cut = await atlas(b, entries.length);
        if (cut[0].width !== w || cut[0].height !== h) bad(`sample image samples/${name}/${b} is not its box's size`);
        return cut;
      }));
      const images = entries.map((_, s) => perBox.map((cut) => cut[s]));
      const opened = inside.filter((i2) => i2).length;
      const openings = opened ? await atlas("interior", opened) : [];
      if (opened && (openings[0].width !== INTERIOR_SIZE[0] || openings[0].height !== INTERIOR_SIZE[1])) {
        bad(`group ${name}: an interior is a ${INTERIOR_SIZE[0]} x ${INTERIOR_SIZE[1]} image`);
      }
      let next = 0;
      const interiors = opened ? inside.map((i2) => i2 ? openings[next++] : null) : null;
      groups.push({ name, boxes: rects, keys, frames, images, interiors });
    }
    return groups;
  }

  // src/render/appearance.ts
  async function readUpdate(payload) {
    if (payload.length < 8) return null;
    const view = new DataView(payload.buffer, payload.byteOffset, payload.byteLength);
    try {
      const image = await decodeImage(payload.subarray(8), "image/webp");
      return { frame: view.getUint32(0, true), x: view.getUint16(4, true), y: view.getUint16(6, true), image };
    } catch {
      return null;
    }
  }
  function applyUpdate(texture, u4) {
    return pasteFaded(texture, u4.image, u4.x, u4.y);
  }
  function pasteFaded(texture, image, x2, y) {
    const tw = texture.width, th = texture.height, w = image.width, h = image.height;
    if (x2 >= tw || y >= th) return false;
    const fadeLeft = x2 > 0, fadeTop = y > 0, fadeRight = x2 + w < tw, fadeBottom = y + h < th;
    for (let j = 0; j < h && y + j < th; j++) {
      for (let i2 = 0; i2 < w && x2 + i2 < tw; i2++) {
        let d = Infinity;
        if (fadeLeft) d = Math.min(d, i2);
        if (fadeRight) d = Math.min(d, w - 1 - i2);
        if (fadeTop) d = Math.min(d, j);
        if (fadeBottom) d = Math.min(d, h - 1 - j);
        const k = Math.min(8, d + 1);
        const s = 4 * (j * w + i2), t = 4 * ((y + j) * tw + x2 + i2);
        for (let c = 0; c < 3; c++) {
          texture.rgba[t + c] = Math.floor((k * image.rgba[s + c] + (8 - k) * texture.rgba[t + c] + 4) / 8);
        }
      }
    }
    return true;
  }

  // src/render/gl.ts
  var VERTEX = `#version 300 es
in vec2 position;
in vec2 uv;
uniform vec2 size;
out vec2 v_uv;
void main() {
  vec2 c = (position + 0.5) / size * 2.0 - 1.0;
  gl_Position = vec4(c.x, -c.y, 0.0, 1.0);
  v_uv = uv;
}`;
  var FRAGMENT = `#version 300 es
precision highp float;
in vec2 v_uv;
uniform sampler2D image;
uniform vec4 tint;
out vec4 colour;
void main() {
  colour = tint.a < 0.0 ? texture(image, v_uv) : tint;
}`;
  var Renderer = class {
    constructor(canvas2) {
      this.canvas = canvas2;
      const gl = canvas2.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true, premultipliedAlpha: false, alpha: false });
      if (!gl) throw new Error("this browser has no WebGL2");
      this.gl = gl;
      const shader = (type, text) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, text);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s) ?? "shader");
        return s;
      };
      const p = gl.createProgram();
      gl.attachShader(p, shader(gl.VERTEX_SHADER, VERTEX));
      gl.attachShader(p, shader(gl.FRAGMENT_SHADER, FRAGMENT));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p) ?? "program");
      this.program = p;
      this.loc = {
        position: gl.getAttribLocation(p, "position"),
        uv: gl.getAttribLocation(p, "uv"),
        size: gl.getUniformLocation(p, "size"),
        tint: gl.getUniformLocation(p, "tint")
      };
      this.positions = gl.createBuffer();
      this.uvs = gl.createBuffer();
      this.indices = gl.createBuffer();
      const sampler = (filter) => {
        const s = gl.createSampler();
        gl.samplerParameteri(s, gl.TEXTURE_MIN_FILTER, filter);
        gl.samplerParameteri(s, gl.TEXTURE_MAG_FILTER, filter);
        gl.samplerParameteri(s, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
        gl.samplerParameteri(s, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
        return s;
      };
      this.nearest = sampler(gl.NEAREST);
      this.linear = sampler(gl.LINEAR);
      this.mouth = gl.createTexture();
      gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
      gl.pixelStorei(gl.PACK_ALIGNMENT, 1);
    }
    /** A texture of ``picture`` (replaced in place when ``into`` is given). */
    upload(picture, into) {
      const gl = this.gl;
      const texture = into?.texture ?? gl.createTexture();
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
    begin(width, height, background, view = [0, 0, width, height]) {
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
    mesh(layer, points, uv, triangles, bilinear, cull) {
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
        gl.frontFace(gl.CW);
        gl.cullFace(gl.BACK);
      } else {
        gl.disable(gl.CULL_FACE);
      }
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indices);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, triangles, gl.STREAM_DRAW);
      gl.drawElements(gl.TRIANGLES, triangles.length, gl.UNSIGNED_INT, 0);
    }
    /** Blends the mouth interior ``patch`` in (its alpha the opening). */
    mouthPatch(patch) {
      const gl = this.gl;
      gl.bindTexture(gl.TEXTURE_2D, this.mouth);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, patch.width, patch.height, 0, gl.RGBA, gl.UNSIGNED_BYTE, patch.rgba);
      const x0 = patch.x0 - 0.5, y0 = patch.y0 - 0.5, x1 = x0 + patch.width, y1 = y0 + patch.height;
      this.quad([x0, y0, x1, y0, x1, y1, x0, y1], { texture: this.mouth, width: patch.width, height: patch.height });
    }
    /** Darkens the whole picture to ``factor`` of its brightness (a frame without a face). */
    dim(factor, width, height) {
      this.quad([-0.5, -0.5, width - 0.5, -0.5, width - 0.5, height - 0.5, -0.5, height - 0.5], null, [0, 0, 0, 1 - factor]);
    }
    quad(corners, layer, tint = [0, 0, 0, -1]) {
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
    attributes(points, uv) {
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
    pixels() {
      const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
      const raw = new Uint8Array(w * h * 4);
      gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, raw);
      const out = new Uint8Array(raw.length);
      for (let y = 0; y < h; y++) out.set(raw.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
      return out;
    }
  };

  // src/render/geometry.ts
  function rotation(yaw, pitch, roll) {
    const [y, p, r] = [yaw, pitch, roll].map((a) => a * Math.PI / 180);
    const ry = [Math.cos(y), 0, Math.sin(y), 0, 1, 0, -Math.sin(y), 0, Math.cos(y)];
    const rx = [1, 0, 0, 0, Math.cos(p), -Math.sin(p), 0, Math.sin(p), Math.cos(p)];
    const rz = [Math.cos(r), -Math.sin(r), 0, Math.sin(r), Math.cos(r), 0, 0, 0, 1];
    return mul3(rz, mul3(rx, ry));
  }
  function mul3(a, b) {
    const out = new Array(9).fill(0);
    for (let i2 = 0; i2 < 3; i2++) for (let j = 0; j < 3; j++) for (let k = 0; k < 3; k++) out[i2 * 3 + j] += a[i2 * 3 + k] * b[k * 3 + j];
    return out;
  }
  function project(vertices, pose) {
    const r = rotation(pose.yaw, pose.pitch, pose.roll);
    const n = vertices.length / 3;
    const points = new Float64Array(n * 2);
    const depth = new Float64Array(n);
    for (let i2 = 0; i2 < n; i2++) {
      const x2 = vertices[3 * i2], y = vertices[3 * i2 + 1], z = vertices[3 * i2 + 2];
      points[2 * i2] = pose.tx + pose.scale * (r[0] * x2 + r[1] * y + r[2] * z);
      points[2 * i2 + 1] = pose.ty - pose.scale * (r[3] * x2 + r[4] * y + r[5] * z);
      depth[i2] = pose.scale * (r[6] * x2 + r[7] * y + r[8] * z);
    }
    return { points, depth };
  }
  function modelIod(m) {
    const a = m.groups.eye_right[0], b = m.groups.eye_left[4];
    return Math.hypot(m.vertices[3 * a] - m.vertices[3 * b], m.vertices[3 * a + 1] - m.vertices[3 * b + 1]);
  }
  function mouthWidth(m, vertices) {
    const g = m.groups.mouth_outer_upper;
    const a = g[0], b = g[g.length - 1];
    return Math.hypot(vertices[3 * b] - vertices[3 * a], vertices[3 * b + 1] - vertices[3 * a + 1]);
  }
  function lipStrip(model) {
    const upper = model.groups.mouth_inner_upper ?? [], lower = model.groups.mouth_inner_lower ?? [];
    if (upper.length !== lower.length) return new Uint32Array(0);
    const out = [];
    for (let i2 = 0; i2 + 1 < upper.length; i2++) {
      const [a, b, c, d] = [upper[i2], upper[i2 + 1], lower[i2 + 1], lower[i2]];
      for (const t of [[a, b, c], [a, c, d]]) if (new Set(t).size === 3) out.push(...t);
    }
    return Uint32Array.from(out);
  }
  function mouthCapped(model) {
    const key = (a, b, c) => [a, b, c].sort((x2, y) => x2 - y).join(",");
    const strip = lipStrip(model), tri = model.triangles, inStrip = /* @__PURE__ */ new Set();
    for (let t = 0; t < strip.length; t += 3) inStrip.add(key(strip[t], strip[t + 1], strip[t + 2]));
    for (let t = 0; t < tri.length; t += 3) if (inStrip.has(key(tri[t], tri[t + 1], tri[t + 2]))) return true;
    return false;
  }
  var Deformer = class {
    constructor(model) {
      this.model = model;
      this.slot = /* @__PURE__ */ new Map();
      /** Per share closed, the model's own closing (sealed takes it back on a capped mouth). */
      this.rest = /* @__PURE__ */ new Map();
      const g = model.groups;
      for (const name of [...CONTOUR_GROUPS, "eye_left", "eye_right"]) {
        if (!g[name]) throw new Error(`the actor's head model lacks the group ${name}`);
      }
      this.knots = [...new Set(CONTOUR_GROUPS.flatMap((n) => g[n]))].sort((a, b) => a - b);
      this.knots.forEach((v2, k) => this.slot.set(v2, k));
      const u4 = g.mouth_inner_upper, l = g.mouth_inner_lower;
      this.inner = [u4.slice(1, -1), l.slice(1, -1)];
      this.weights = this.spread();
      this.capped = mouthCapped(model);
    }
    spread() {
      const m = this.model, g = m.groups, v2 = m.vertices;
      const n = v2.length / 3, k = this.knots.length;
      const iod = modelIod(m);
      const eyes = [...g.eye_left, ...g.eye_right];
      const eyeY = eyes.reduce((s, i2) => s + v2[3 * i2 + 1], 0) / eyes.length;
      const mu = g.mouth_outer_upper;
      const mouthY = (v2[3 * mu[0] + 1] + v2[3 * mu[mu.length - 1] + 1]) / 2;
      const slots = (names) => [...new Set(names.flatMap((x2) => g[x2]))].sort((a, b) => a - b).map((i2) => this.slot.get(i2));
      const sets = {
        upper: slots(["mouth_outer_upper", "mouth_inner_upper"]),
        lower: slots(["mouth_outer_lower", "mouth_inner_lower"]),
        brows: slots(CONTOUR_GROUPS.filter((x2) => x2.startsWith("brow")))
      };
      const anchorList = [];
      for (const name of ["eye_left", "eye_right", "nose"]) if (g[name]) anchorList.push(...g[name]);
      if (g.face_outline) anchorList.push(...g.face_outline.filter((i2) => v2[3 * i2 + 1] > mouthY));
      const knotSet = new Set(this.knots);
      const anchors = [...new Set(anchorList)].filter((i2) => !knotSet.has(i2)).sort((a, b) => a - b);
      const soft2 = (SOFTEN * iod) ** 2, far = 1 / (REACH * iod) ** 2;
      const d2 = (a, b) => (v2[3 * a] - v2[3 * b]) ** 2 + (v2[3 * a + 1] - v2[3 * b + 1]) ** 2 + (v2[3 * a + 2] - v2[3 * b + 2]) ** 2;
      const w = new Float64Array(n * k);
      for (let j = 0; j < n; j++) {
        const own = this.slot.get(j);
        if (own !== void 0) {
          w[j * k + own] = 1;
          continue;
        }
        const y = v2[3 * j + 1];
        const chosen = y > eyeY ? sets.brows : y >= mouthY ? sets.upper : sets.lower;
        const ws = chosen.map((s) => 1 / (d2(this.knots[s], j) + soft2));
        let rest = far;
        for (const a of anchors) if (a !== j) rest += 1 / (d2(a, j) + soft2);
        const total = ws.reduce((s, x2) => s + x2, 0) + rest;
        chosen.forEach((s, i2) => {
          w[j * k + s] = ws[i2] / total;
        });
      }
      return w;
    }
    /** The model's vertices moved by knot ``offsets`` (K*2, model units) times ``gain``. */
    vertices(offsets, gain = 1) {
      const out = Float64Array.from(this.model.vertices);
      this.add(out, offsets, gain);
      return out;
    }
    add(out, offsets, gain) {
      const k = this.knots.length, n = out.length / 3, w = this.weights;
      for (let j = 0; j < n; j++) {
        let dx = 0, dy = 0;
        for (let s = 0; s < k; s++) {
          const c = w[j * k + s];
          if (c !== 0) {
            dx += c * offsets[2 * s];
            dy += c * offsets[2 * s + 1];
          }
        }
        out[3 * j] += gain * dx;
        out[3 * j + 1] += gain * dy;
      }
    }
    /** ``vertices`` with the lips shut where the inner lips lie closer than ``closed`` times the
     * mouth's width (Deformer.sealed): a copy. On a capped mouth what this does to the model's own
     * vertices is taken back, so that the key frame's mouth is drawn as it was fitted. */
    sealed(vertices, closed) {
      const close = this.closing(vertices, closed);
      if (close === null) return vertices;
      if (this.capped && !this.rest.has(closed)) this.rest.set(closed, this.closing(this.model.vertices, closed));
      const rest = this.capped ? this.rest.get(closed) ?? null : null;
      if (rest !== null) for (let i2 = 0; i2 < close.length; i2++) close[i2] -= rest[i2];
      const out = Float64Array.from(vertices);
      this.add(out, close, 1);
      return out;
    }
    /** The K*2 knot moves that shut the lips of ``vertices`` as sealed says, model units (null where
     * the inner lips' knot counts differ or the mouth has no width). */
    closing(vertices, closed) {
      const [upper, lower] = this.inner;
      const g = this.model.groups.mouth_outer_upper;
      const c0 = g[0], c1 = g[g.length - 1];
      const ax = vertices[3 * c1] - vertices[3 * c0], ay = vertices[3 * c1 + 1] - vertices[3 * c0 + 1];
      const width = mouthWidth(this.model, vertices);
      if (upper.length !== lower.length || width <= 0) return null;
      const ux = -ay / width, uy = ax / width;
      const limit = closed * width;
      const close = new Float64Array(this.knots.length * 2);
      upper.forEach((u4, i2) => {
        const l = lower[i2];
        const gap = (vertices[3 * u4] - vertices[3 * l]) * ux + (vertices[3 * u4 + 1] - vertices[3 * l + 1]) * uy;
        const shown2 = gap < limit ? 0 : gap < 2 * limit ? 2 * (gap - limit) : gap;
        const half = 0.5 * (gap - shown2);
        const su = this.slot.get(u4), sl = this.slot.get(l);
        close[2 * su] = -half * ux;
        close[2 * su + 1] = -half * uy;
        close[2 * sl] = half * ux;
        close[2 * sl + 1] = half * uy;
      });
      return close;
    }
  };
  function closeLids(m, vertices, closure) {
    const out = Float64Array.from(vertices);
    ["eye_right", "eye_left"].forEach((name, e) => {
      const c = closure[e], ring = m.groups[name];
      if (!c) return;
      UPPER_LID.forEach((p, i2) => {
        const up = ring[p], low = ring[LOWER_LID[i2]];
        for (let d = 0; d < 3; d++) out[3 * up + d] = vertices[3 * up + d] + c * (vertices[3 * low + d] - vertices[3 * up + d]);
      });
    });
    return out;
  }
  function shownPose(measured, rest, key, inScene) {
    if (!inScene) return { ...measured };
    const ratio = rest.scale / key.scale;
    return {
      yaw: rest.yaw + measured.yaw - key.yaw,
      pitch: rest.pitch + measured.pitch - key.pitch,
      roll: rest.roll + measured.roll - key.roll,
      scale: rest.scale * measured.scale / key.scale,
      tx: rest.tx + ratio * (measured.tx - key.tx),
      ty: rest.ty + ratio * (measured.ty - key.ty)
    };
  }
  function poseFromValues(v2) {
    return { yaw: v2[0], pitch: v2[1], roll: v2[2], scale: Math.exp(v2[3]), tx: v2[4], ty: v2[5] };
  }

  // src/imaging/filters.ts
  function rint(x2) {
    const f = Math.floor(x2), d = x2 - f;
    if (d > 0.5) return f + 1;
    if (d < 0.5) return f;
    return f % 2 === 0 ? f : f + 1;
  }
  function reflect101(p, len) {
    if (len === 1) return 0;
    while (p < 0 || p >= len) p = p < 0 ? -p : 2 * len - 2 - p;
    return p;
  }
  var clampIndex = (p, len) => p < 0 ? 0 : p >= len ? len - 1 : p;
  function erodeEllipse(src, w, h, k) {
    const r = k >> 1, c = k >> 1;
    const half = [];
    for (let i2 = 0; i2 < k; i2++) {
      const dy = i2 - r;
      const dx = rint(c * Math.sqrt((r * r - dy * dy) / (r * r)));
      const j1 = Math.max(c - dx, 0), j2 = Math.min(c + dx + 1, k);
      half.push(j2 > j1 ? Math.min(c - j1, j2 - 1 - c) : -1);
    }
    const runs = [src];
    const most = Math.max(...half);
    for (let m = 1; m <= most; m++) {
      const prev = runs[m - 1], next = new Float32Array(w * h);
      for (let y = 0; y < h; y++) {
        const o = y * w;
        for (let x2 = 0; x2 < w; x2++) {
          let v2 = prev[o + x2];
          if (x2 - m >= 0 && src[o + x2 - m] < v2) v2 = src[o + x2 - m];
          if (x2 + m < w && src[o + x2 + m] < v2) v2 = src[o + x2 + m];
          next[o + x2] = v2;
        }
      }
      runs.push(next);
    }
    const out = new Float32Array(w * h).fill(Infinity);
    for (let i2 = 0; i2 < k; i2++) {
      if (half[i2] < 0) continue;
      const run = runs[half[i2]], dy = i2 - r;
      for (let y = Math.max(0, -dy); y < Math.min(h, h - dy); y++) {
        const o = y * w, q = (y + dy) * w;
        for (let x2 = 0; x2 < w; x2++) if (run[q + x2] < out[o + x2]) out[o + x2] = run[q + x2];
      }
    }
    return out;
  }
  var gaussianSize = (sigma) => rint(sigma * 4 * 2 + 1) | 1;
  function gaussianBlur(src, w, h, ch, sigma, [x0, y0, x1, y1]) {
    const n = gaussianSize(sigma), half = n >> 1;
    const kernel = new Float64Array(n);
    let sum2 = 0;
    for (let i2 = 0; i2 < n; i2++) {
      const x2 = i2 - (n - 1) * 0.5;
      kernel[i2] = Math.exp(-0.5 / (sigma * sigma) * x2 * x2);
      sum2 += kernel[i2];
    }
    for (let i2 = 0; i2 < n; i2++) kernel[i2] = Math.fround(kernel[i2] / sum2);
    const out = new Float32Array(w * h * ch);
    if (x1 <= x0 || y1 <= y0) return out;
    const span = (x1 - x0) * ch;
    const rows = /* @__PURE__ */ new Map();
    const pad = new Float32Array((x1 - x0 + 2 * half) * ch), acc = new Float64Array(span);
    const filtered = (y) => {
      let row = rows.get(y);
      if (row) return row;
      for (let x2 = 0; x2 < x1 - x0 + 2 * half; x2++) {
        const from = (y * w + reflect101(x0 + x2 - half, w)) * ch;
        for (let c = 0; c < ch; c++) pad[x2 * ch + c] = src[from + c];
      }
      const along = new Float64Array(span);
      for (let i2 = 0; i2 < n; i2++) {
        const kv = kernel[i2], o = i2 * ch;
        for (let q = 0; q < span; q++) along[q] += kv * pad[o + q];
      }
      row = Float32Array.from(along);
      rows.set(y, row);
      return row;
    };
    for (let y = y0; y < y1; y++) {
      acc.fill(0);
      for (let i2 = 0; i2 < n; i2++) {
        const kv = kernel[i2], row = filtered(reflect101(y + i2 - half, h));
        for (let q = 0; q < span; q++) acc[q] += kv * row[q];
      }
      out.set(acc, (y * w + x0) * ch);
    }
    return out;
  }
  function percentile(a, q) {
    a.sort();
    const at = q / 100 * (a.length - 1), lo = Math.floor(at), t = at - lo;
    if (lo + 1 >= a.length) return a[a.length - 1];
    const d = a[lo + 1] - a[lo];
    return t >= 0.5 ? a[lo + 1] - d * (1 - t) : a[lo] + d * t;
  }
  function median(a) {
    a.sort();
    const m = a.length >> 1;
    return a.length % 2 ? a[m] : (a[m - 1] + a[m]) / 2;
  }

  // src/imaging/inpaint.ts
  var KNOWN = 0;
  var BAND = 1;
  var INSIDE = 2;
  var CHANGE = 3;
  var MarchQueue = class {
    constructor(capacity) {
      this.size = 0;
      this.count = 0;
      this.t = new Float64Array(capacity);
      this.seq = new Float64Array(capacity);
      this.at = new Int32Array(capacity);
    }
    less(a, b) {
      return this.t[a] < this.t[b] || this.t[a] === this.t[b] && this.seq[a] < this.seq[b];
    }
    swap(a, b) {
      const { t, seq, at } = this;
      const tt = t[a], ts = seq[a], ta = at[a];
      t[a] = t[b];
      seq[a] = seq[b];
      at[a] = at[b];
      t[b] = tt;
      seq[b] = ts;
      at[b] = ta;
    }
    push(index, t) {
      let n = this.size++;
      this.t[n] = t;
      this.seq[n] = this.count++;
      this.at[n] = index;
      while (n > 0) {
        const p = n - 1 >> 1;
        if (!this.less(n, p)) break;
        this.swap(n, p);
        n = p;
      }
    }
    /** The index (row * cols + col) of the element popped. */
    pop() {
      const top = this.at[0];
      const last = --this.size;
      this.t[0] = this.t[last];
      this.seq[0] = this.seq[last];
      this.at[0] = this.at[last];
      let n = 0;
      for (; ; ) {
        const l = 2 * n + 1, r = l + 1;
        let m = n;
        if (l < last && this.less(l, m)) m = l;
        if (r < last && this.less(r, m)) m = r;
        if (m === n) break;
        this.swap(n, m);
        n = m;
      }
      return top;
    }
  };
  function solve(i1, j1, i2, j2, f, t, ec2) {
    const a11 = t[i1 * ec2 + j1], a22 = t[i2 * ec2 + j2], m12 = Math.min(a11, a22);
    let sol;
    if (f[i1 * ec2 + j1] !== INSIDE) {
      if (f[i2 * ec2 + j2] !== INSIDE) {
        sol = Math.abs(a11 - a22) >= 1 ? 1 + m12 : (a11 + a22 + Math.sqrt(2 - (a11 - a22) * (a11 - a22))) * 0.5;
      } else sol = 1 + a11;
    } else if (f[i2 * ec2 + j2] !== INSIDE) sol = 1 + a22;
    else sol = 1 + m12;
    return Math.fround(sol);
  }
  function solve4(i2, j, f, t, ec2) {
    return Math.min(
      solve(i2 - 1, j, i2, j - 1, f, t, ec2),
      solve(i2 + 1, j, i2, j - 1, f, t, ec2),
      solve(i2 - 1, j, i2, j + 1, f, t, ec2),
      solve(i2 + 1, j, i2, j + 1, f, t, ec2)
    );
  }
  function dilate(src, er, ec2, r, cross = false) {
    const at = (i2, j) => i2 >= 0 && i2 < er && j >= 0 && j < ec2 ? src[i2 * ec2 + j] : 0;
    const out = new Uint8Array(er * ec2);
    if (cross) {
      for (let i2 = 0; i2 < er; i2++) {
        for (let j = 0; j < ec2; j++) out[i2 * ec2 + j] = Math.max(at(i2, j), at(i2 - 1, j), at(i2 + 1, j), at(i2, j - 1), at(i2, j + 1));
      }
      return out;
    }
    const rows = new Uint8Array(er * ec2);
    for (let i2 = 0; i2 < er; i2++) {
      for (let j = 0; j < ec2; j++) {
        let m = 0;
        for (let d = Math.max(0, j - r); d <= Math.min(ec2 - 1, j + r); d++) if (src[i2 * ec2 + d] > m) m = src[i2 * ec2 + d];
        rows[i2 * ec2 + j] = m;
      }
    }
    for (let i2 = 0; i2 < er; i2++) {
      for (let j = 0; j < ec2; j++) {
        let m = 0;
        for (let d = Math.max(0, i2 - r); d <= Math.min(er - 1, i2 + r); d++) if (rows[d * ec2 + j] > m) m = rows[d * ec2 + j];
        out[i2 * ec2 + j] = m;
      }
    }
    return out;
  }
  function zeroBorder(a, er, ec2) {
    a.fill(0, 0, ec2);
    a.fill(0, (er - 1) * ec2, er * ec2);
    for (let i2 = 1; i2 < er - 1; i2++) a[i2 * ec2] = a[i2 * ec2 + ec2 - 1] = 0;
  }
  function inpaintTelea(img, mask, w, h, inpaintRange) {
    const range = Math.min(Math.max(rint(inpaintRange), 1), 100);
    const ec2 = w + 2, er = h + 2;
    const f = new Uint8Array(er * ec2);
    for (let y = 0; y < h; y++) for (let x2 = 0; x2 < w; x2++) if (mask[y * w + x2]) f[(y + 1) * ec2 + x2 + 1] = INSIDE;
    zeroBorder(f, er, ec2);
    const t = new Float32Array(er * ec2).fill(1e6);
    const band = dilate(f, er, ec2, 1, true);
    for (let k = 0; k < band.length; k++) band[k] = Math.max(band[k] - f[k], 0);
    zeroBorder(band, er, ec2);
    const heap = new MarchQueue(er * ec2);
    for (let k = 0; k < band.length; k++) if (band[k]) {
      heap.push(k, 0);
      t[k] = 0;
    }
    if (heap.size === 0) return;
    const out = dilate(f, er, ec2, range);
    for (let k = 0; k < out.length; k++) out[k] = Math.max(out[k] - f[k], 0);
    const outer = new MarchQueue(er * ec2);
    for (let k = 0; k < band.length; k++) if (band[k]) outer.push(k, 0);
    for (let k = 0; k < out.length; k++) out[k] = Math.max(out[k] - band[k], 0);
    zeroBorder(out, er, ec2);
    while (outer.size) {
      const at = outer.pop(), ii = Math.floor(at / ec2), jj = at - ii * ec2;
      out[at] = CHANGE;
      for (let q = 0; q < 4; q++) {
        const i2 = q === 0 ? ii - 1 : q === 2 ? ii + 1 : ii, j = q === 1 ? jj - 1 : q === 3 ? jj + 1 : jj;
        if (i2 <= 0 || j <= 0 || i2 >= er || j >= ec2) continue;
        if (out[i2 * ec2 + j] === INSIDE) {
          const dist2 = solve4(i2, j, out, t, ec2);
          t[i2 * ec2 + j] = dist2;
          out[i2 * ec2 + j] = BAND;
          outer.push(i2 * ec2 + j, dist2);
        }
      }
    }
    for (let k = 0; k < out.length; k++) if (out[k] === CHANGE) t[k] = -t[k];
    const fr = Math.fround;
    const side = 2 * range + 1;
    const reach = new Int32Array(side), dst = new Float32Array(side * side);
    for (let dk = -range; dk <= range; dk++) {
      while ((reach[dk + range] + 1) ** 2 + dk * dk <= range * range) reach[dk + range]++;
      for (let dl = -range; dl <= range; dl++) {
        const len = dk * dk + dl * dl;
        dst[(dk + range) * side + dl + range] = fr(1 / (len * Math.sqrt(len)));
      }
    }
    const ia = new Float64Array(3), jx = new Float64Array(3), jy = new Float64Array(3);
    const rowStep = w * 3;
    while (heap.size) {
      const at = heap.pop(), ii = Math.floor(at / ec2), jj = at - ii * ec2;
      f[at] = KNOWN;
      for (let q = 0; q < 4; q++) {
        const i2 = q === 0 ? ii - 1 : q === 2 ? ii + 1 : ii, j = q === 1 ? jj - 1 : q === 3 ? jj + 1 : jj;
        if (i2 <= 1 || j <= 1 || i2 > er - 1 || j > ec2 - 1) continue;
        const ij = i2 * ec2 + j;
        if (f[ij] !== INSIDE) continue;
        const dist2 = solve4(i2, j, f, t, ec2);
        t[ij] = dist2;
        let gtx, gty;
        if (f[ij + 1] !== INSIDE) gtx = f[ij - 1] !== INSIDE ? fr(fr(t[ij + 1] - t[ij - 1]) * 0.5) : fr(t[ij + 1] - t[ij]);
        else gtx = f[ij - 1] !== INSIDE ? fr(t[ij] - t[ij - 1]) : 0;
        if (f[ij + ec2] !== INSIDE) gty = f[ij - ec2] !== INSIDE ? fr(fr(t[ij + ec2] - t[ij - ec2]) * 0.5) : fr(t[ij + ec2] - t[ij]);
        else gty = f[ij - ec2] !== INSIDE ? fr(t[ij] - t[ij - ec2]) : 0;
        ia.fill(0);
        jx.fill(0);
        jy.fill(0);
        let s = fr(1e-20);
        const tij = t[ij];
        for (let k = Math.max(i2 - range, 1); k <= Math.min(i2 + range, er - 2); k++) {
          const ry = i2 - k, half = reach[k - i2 + range], drow = (k - i2 + range) * side + range - j;
          const km = k - 1 + +(k === 1), kp = k - 1 - +(k === er - 2), rowM = km * rowStep;
          const fry = fr(ry * gty);
          for (let l = Math.max(j - half, 1); l <= Math.min(j + half, ec2 - 2); l++) {
            const kl = k * ec2 + l;
            if (f[kl] === INSIDE) continue;
            const rx = j - l;
            const lev = fr(1 / fr(1 + Math.abs(fr(t[kl] - tij))));
            let dir = fr(fr(rx * gtx) + fry);
            if (Math.abs(dir) <= 0.01) dir = fr(1e-6);
            const wt = Math.abs(fr(fr(dst[drow + l] * lev) * dir));
            const lm = l - 1 + +(l === 1), lp = l - 1 - +(l === ec2 - 2);
            const right = f[kl + 1] !== INSIDE, left = f[kl - 1] !== INSIDE;
            const below = f[kl + ec2] !== INSIDE, above = f[kl - ec2] !== INSIDE;
            const here = (km * w + lm) * 3;
            for (let c = 0; c < 3; c++) {
              let gx, gy;
              if (right) {
                gx = left ? (img[rowM + (lp + 1) * 3 + c] - img[here - 3 + c]) * 2 : img[rowM + (lp + 1) * 3 + c] - img[here + c];
              } else gx = left ? img[rowM + lp * 3 + c] - img[here - 3 + c] : 0;
              if (below) {
                gy = above ? (img[(kp + 1) * rowStep + lm * 3 + c] - img[here - rowStep + c]) * 2 : img[(kp + 1) * rowStep + lm * 3 + c] - img[here + c];
              } else gy = above ? img[kp * rowStep + lm * 3 + c] - img[here - rowStep + c] : 0;
              ia[c] = fr(ia[c] + fr(wt * img[here + c]));
              jx[c] = fr(jx[c] - fr(wt * fr(gx * rx)));
              jy[c] = fr(jy[c] - fr(wt * fr(gy * ry)));
            }
            s = fr(s + wt);
          }
        }
        for (let c = 0; c < 3; c++) {
          const norm = fr(fr(Math.sqrt(fr(fr(jx[c] * jx[c]) + fr(jy[c] * jy[c])))) + fr(1e-20));
          const sat = fr(fr(fr(ia[c] / s) + fr(fr(jx[c] + jy[c]) / norm)) + 0.5);
          img[((i2 - 1) * w + j - 1) * 3 + c] = Math.min(Math.max(rint(sat), 0), 255);
        }
        f[ij] = BAND;
        heap.push(ij, dist2);
      }
    }
  }

  // src/imaging/polygon.ts
  var XY_SHIFT = 16;
  var XY_ONE = 1 << XY_SHIFT;
  var SLOPE_CORR = [
    181,
    181,
    181,
    182,
    182,
    183,
    184,
    185,
    187,
    188,
    190,
    192,
    194,
    196,
    198,
    201,
    203,
    206,
    209,
    211,
    214,
    218,
    221,
    224,
    227,
    231,
    235,
    238,
    242,
    246,
    250,
    254
  ];
  var FILTER = [
    168,
    177,
    185,
    194,
    202,
    210,
    218,
    224,
    231,
    236,
    241,
    246,
    249,
    252,
    254,
    254,
    254,
    254,
    252,
    249,
    246,
    241,
    236,
    231,
    224,
    218,
    210,
    202,
    194,
    185,
    177,
    168,
    158,
    149,
    140,
    131,
    122,
    114,
    105,
    97,
    89,
    82,
    75,
    68,
    62,
    56,
    50,
    45,
    40,
    36,
    32,
    28,
    25,
    22,
    19,
    16,
    14,
    12,
    11,
    9,
    8,
    7,
    5,
    5
  ];
  var sar = (v2, s) => Math.floor(v2 / 2 ** s);
  function clipLine(width, height, p) {
    const right = width - 1, bottom = height - 1;
    if (width <= 0 || height <= 0) return false;
    let [x1, y1, x2, y2] = p;
    let c1 = +(x1 < 0) + +(x1 > right) * 2 + +(y1 < 0) * 4 + +(y1 > bottom) * 8;
    let c2 = +(x2 < 0) + +(x2 > right) * 2 + +(y2 < 0) * 4 + +(y2 > bottom) * 8;
    if ((c1 & c2) === 0 && (c1 | c2) !== 0) {
      if (c1 & 12) {
        const a = c1 < 8 ? 0 : bottom;
        x1 += Math.trunc((a - y1) * (x2 - x1) / (y2 - y1));
        y1 = a;
        c1 = +(x1 < 0) + +(x1 > right) * 2;
      }
      if (c2 & 12) {
        const a = c2 < 8 ? 0 : bottom;
        x2 += Math.trunc((a - y2) * (x2 - x1) / (y2 - y1));
        y2 = a;
        c2 = +(x2 < 0) + +(x2 > right) * 2;
      }
      if ((c1 & c2) === 0 && (c1 | c2) !== 0) {
        if (c1) {
          const a = c1 === 1 ? 0 : right;
          y1 += Math.trunc((a - x1) * (y2 - y1) / (x2 - x1));
          x1 = a;
          c1 = 0;
        }
        if (c2) {
          const a = c2 === 1 ? 0 : right;
          y2 += Math.trunc((a - x2) * (y2 - y1) / (x2 - x1));
          x2 = a;
          c2 = 0;
        }
      }
    }
    p[0] = x1;
    p[1] = y1;
    p[2] = x2;
    p[3] = y2;
    return (c1 | c2) === 0;
  }
  function lineAA(cv, ax0, ay0, ax1, ay1) {
    const { img, w, h, colour } = cv;
    const ch = colour.length;
    const p = [ax0 - 2 * XY_ONE, ay0 - 2 * XY_ONE, ax1 - 2 * XY_ONE, ay1 - 2 * XY_ONE];
    if (!clipLine((w - 5) * XY_ONE + 1, (h - 5) * XY_ONE + 1, p)) return;
    let [x1, y1, x2, y2] = p;
    let dx = x2 - x1, dy = y2 - y1;
    const ax = Math.abs(dx), ay = Math.abs(dy);
    let xStep, yStep, ecount, slope, i2, j;
    const horizontal = ax > ay;
    if (horizontal) {
      if (dx < 0) {
        dy = -dy;
        [x1, x2] = [x2, x1];
        [y1, y2] = [y2, y1];
      }
      xStep = XY_ONE;
      yStep = Math.trunc(dy * XY_ONE / (ax | 1));
      x2 += XY_ONE;
      ecount = sar(x2, XY_SHIFT) - sar(x1, XY_SHIFT);
      j = -(x1 - sar(x1, XY_SHIFT) * XY_ONE);
      y1 += sar(yStep * j, XY_SHIFT) + (XY_ONE >> 1);
      slope = sar(yStep, XY_SHIFT - 5) & 63;
      slope ^= yStep < 0 ? 63 : 0;
      i2 = sar(x1, XY_SHIFT - 7) & 120;
      j = sar(x2, XY_SHIFT - 7) & 120;
    } else {
      if (dy < 0) {
        dx = -dx;
        [x1, x2] = [x2, x1];
        [y1, y2] = [y2, y1];
      }
      xStep = Math.trunc(dx * XY_ONE / (ay | 1));
      yStep = XY_ONE;
      y2 += XY_ONE;
      ecount = sar(y2, XY_SHIFT) - sar(y1, XY_SHIFT);
      j = -(y1 - sar(y1, XY_SHIFT) * XY_ONE);
      x1 += sar(xStep * j, XY_SHIFT) + (XY_ONE >> 1);
      slope = sar(xStep, XY_SHIFT - 5) & 63;
      slope ^= xStep < 0 ? 63 : 0;
      i2 = sar(y1, XY_SHIFT - 7) & 120;
      j = sar(y2, XY_SHIFT - 7) & 120;
    }
    slope = slope & 32 ? 256 : SLOPE_CORR[slope];
    const ep = new Array(9);
    {
      const t0 = slope << 7, t1 = (120 - i2 | 4) * slope, t2 = (j | 4) * slope;
      ep[0] = 0;
      ep[8] = slope;
      ep[1] = ep[3] = (j - i2 & 120 | 4) * slope >> 8 & 511;
      ep[2] = t1 >> 8 & 511;
      ep[4] = (j - i2 + 128 | 4) * slope >> 8 & 511;
      ep[5] = t1 + t0 >> 8 & 511;
      ep[6] = t2 >> 8 & 511;
      ep[7] = t2 + t0 >> 8 & 511;
    }
    const put = (at, a) => {
      for (let c = 0; c < ch; c++) {
        for (let n = 0; n < 2; n++) img[at * ch + c] += (colour[c] - img[at * ch + c]) * a + 127 >> 8;
      }
    };
    const index = (n) => n >= 2 ? 2 : n;
    let scount = 0;
    if (horizontal) {
      let col = sar(x1, XY_SHIFT) + 2;
      while (ecount >= 0) {
        const row = sar(y1, XY_SHIFT) - 1 + 2;
        const corr = ep[index(scount) * 3 + index(ecount)];
        const dist2 = sar(y1, XY_SHIFT - 5) & 31;
        put(row * w + col, corr * FILTER[dist2 + 32] >> 8 & 255);
        put((row + 1) * w + col, corr * FILTER[dist2] >> 8 & 255);
        put((row + 2) * w + col, corr * FILTER[63 - dist2] >> 8 & 255);
        y1 += yStep;
        col++;
        scount++;
        ecount--;
      }
    } else {
      let row = sar(y1, XY_SHIFT) + 2;
      while (ecount >= 0) {
        const col = sar(x1, XY_SHIFT) - 1 + 2;
        const corr = ep[index(scount) * 3 + index(ecount)];
        const dist2 = sar(x1, XY_SHIFT - 5) & 31;
        put(row * w + col, corr * FILTER[dist2 + 32] >> 8 & 255);
        put(row * w + col + 1, corr * FILTER[dist2] >> 8 & 255);
        put(row * w + col + 2, corr * FILTER[63 - dist2] >> 8 & 255);
        x1 += xStep;
        row++;
        scount++;
        ecount--;
      }
    }
  }
  function lineAAShifted(cv, a, b, shift) {
    const s = 2 ** (XY_SHIFT - shift);
    lineAA(cv, a[0] * s, a[1] * s, b[0] * s, b[1] * s);
  }
  function fillPolyAA(cv, pts, shift) {
    const { img, w, h, colour } = cv;
    const ch = colour.length;
    const count = pts.length / 2;
    const delta = 1 << shift >> 1;
    const edges = [];
    let p0x = pts[2 * count - 2] * 2 ** (XY_SHIFT - shift), p0y = sar(pts[2 * count - 1] + delta, shift);
    for (let i3 = 0; i3 < count; i3++) {
      const p1x = pts[2 * i3] * 2 ** (XY_SHIFT - shift), p1y = sar(pts[2 * i3 + 1] + delta, shift);
      lineAA(cv, p0x, p0y * XY_ONE, p1x, p1y * XY_ONE);
      if (p0y !== p1y) {
        const up = p0y < p1y;
        edges.push({
          y0: up ? p0y : p1y,
          y1: up ? p1y : p0y,
          x: up ? p0x : p1x,
          dx: Math.trunc((p1x - p0x) / (p1y - p0y)),
          next: null
        });
      }
      p0x = p1x;
      p0y = p1y;
    }
    const total = edges.length;
    if (total < 2) return;
    let yMax = -Infinity, yMin = Infinity, xMax = -Infinity, xMin = Infinity;
    for (const e1 of edges) {
      const xEnd = e1.x + (e1.y1 - e1.y0) * e1.dx;
      yMin = Math.min(yMin, e1.y0);
      yMax = Math.max(yMax, e1.y1);
      xMin = Math.min(xMin, e1.x, xEnd);
      xMax = Math.max(xMax, e1.x, xEnd);
    }
    if (yMax < 0 || yMin >= h || xMax < 0 || xMin >= w * XY_ONE) return;
    edges.sort((a, b) => a.y0 !== b.y0 ? a.y0 - b.y0 : a.x !== b.x ? a.x - b.x : a.dx - b.dx);
    edges.push({ y0: 2 ** 31 - 1, y1: 0, x: 0, dx: 0, next: null });
    const tmp = { y0: 2 ** 31 - 1, y1: 0, x: 0, dx: 0, next: null };
    let i2 = 0;
    let e = edges[0];
    yMax = Math.min(yMax, h);
    for (let y = e.y0; y < yMax; y++) {
      let prelast = tmp, last = tmp.next, keep;
      let sortFlag = false, draw = false;
      const clip = y < 0;
      while (last || e.y0 === y) {
        if (last && last.y1 === y) {
          prelast.next = last.next;
          last = last.next;
          continue;
        }
        keep = prelast;
        if (last && (e.y0 > y || last.x < e.x)) {
          prelast = last;
          last = last.next;
        } else if (i2 < total) {
          prelast.next = e;
          e.next = last;
          prelast = e;
          e = edges[++i2];
        } else break;
        if (draw) {
          if (!clip) {
            let x1, x2;
            if (keep.x > prelast.x) {
              x1 = sar(prelast.x + XY_ONE - 1, XY_SHIFT);
              x2 = sar(keep.x, XY_SHIFT);
            } else {
              x1 = sar(keep.x + XY_ONE - 1, XY_SHIFT);
              x2 = sar(prelast.x, XY_SHIFT);
            }
            if (x1 < w && x2 >= 0) {
              x1 = Math.max(x1, 0);
              x2 = Math.min(x2, w - 1);
              for (let x3 = x1; x3 <= x2; x3++) for (let c = 0; c < ch; c++) img[(y * w + x3) * ch + c] = colour[c];
            }
          }
          keep.x += keep.dx;
          prelast.x += prelast.dx;
        }
        draw = !draw;
      }
      keep = null;
      do {
        prelast = tmp;
        last = tmp.next;
        while (last !== keep && last !== null && last.next !== null) {
          const te = last.next;
          if (last.x > te.x) {
            prelast.next = te;
            last.next = te.next;
            te.next = last;
            prelast = te;
            sortFlag = true;
          } else {
            prelast = last;
            last = te;
          }
        }
        keep = prelast;
      } while (sortFlag && keep !== tmp.next && keep !== tmp);
    }
  }

  // src/render/eyes.ts
  var EyeFrame = class _EyeFrame {
    constructor(origin, axes) {
      this.origin = origin;
      this.axes = axes;
    }
    /** The frame of an eye ring of 8 points (corner, 3 upper, corner, 3 lower), px (x, y) pairs. */
    static of(ring) {
      const [a, b] = ring[0] <= ring[8] ? [0, 8] : [8, 0];
      const ex = ring[b] - ring[a], ey = ring[b + 1] - ring[a + 1];
      return new _EyeFrame([(ring[a] + ring[b]) / 2, (ring[a + 1] + ring[b + 1]) / 2], [ex, ey, -ey, ex]);
    }
    /** The eye's width, px. */
    get width() {
      return Math.hypot(this.axes[0], this.axes[1]);
    }
    /** Texture (x, y) px of eye coordinates (u, v). */
    toImage(u4, v2) {
      const a = this.axes;
      return [this.origin[0] + (u4 * a[0] + v2 * a[2]), this.origin[1] + (u4 * a[1] + v2 * a[3])];
    }
  };
  var PATCH_ROWS = rint((SPAN_V[1] - SPAN_V[0]) * DENSITY) + 1;
  var PATCH_COLS = rint((SPAN_U[1] - SPAN_U[0]) * DENSITY) + 1;
  var uOf = (col) => SPAN_U[0] + col / DENSITY;
  var vOf = (row) => SPAN_V[0] + row / DENSITY;
  var colOf = (u4) => rint((u4 - SPAN_U[0]) * DENSITY);
  var rowOf = (v2) => rint((v2 - SPAN_V[0]) * DENSITY);
  function eyePatch(tex, frame) {
    const a = frame.axes;
    const start = frame.toImage(SPAN_U[0], SPAN_V[0]);
    const m = [a[0] / DENSITY, a[2] / DENSITY, start[0], a[1] / DENSITY, a[3] / DENSITY, start[1]];
    const { width: w, height: h, rgba } = tex;
    const out = new Float64Array(PATCH_ROWS * PATCH_COLS);
    const rgb = [0, 0, 0];
    for (let r = 0; r < PATCH_ROWS; r++) {
      const x0 = rint((m[1] * r + m[2]) * 1024) + 16, y0 = rint((m[4] * r + m[5]) * 1024) + 16;
      for (let c = 0; c < PATCH_COLS; c++) {
        const X = x0 + rint(m[0] * c * 1024) >> 5, Y = y0 + rint(m[3] * c * 1024) >> 5;
        const sx = X >> 5, sy = Y >> 5, fx = X & 31, fy = Y & 31;
        const xa = clampIndex(sx, w), xb = clampIndex(sx + 1, w), ya = clampIndex(sy, h), yb = clampIndex(sy + 1, h);
        const w00 = (32 - fx) * (32 - fy), w01 = fx * (32 - fy), w10 = (32 - fx) * fy, w11 = fx * fy;
        for (let k = 0; k < 3; k++) {
          const s = w00 * rgba[(ya * w + xa) * 4 + k] + w01 * rgba[(ya * w + xb) * 4 + k] + w10 * rgba[(yb * w + xa) * 4 + k] + w11 * rgba[(yb * w + xb) * 4 + k];
          rgb[k] = s + 512 >> 10;
        }
        out[r * PATCH_COLS + c] = rgb[0] * 4899 + rgb[1] * 9617 + rgb[2] * 1868 + 8192 >> 14;
      }
    }
    return out;
  }
  function peak(values, i2) {
    if (i2 > 0 && i2 < values.length - 1) {
      const a = values[i2 - 1], b = values[i2], c = values[i2 + 1];
      const d = a - 2 * b + c;
      if (d !== 0) return i2 + Math.min(Math.max(0.5 * (a - c) / d, -0.5), 0.5);
    }
    return i2;
  }
  function findIris(patch) {
    const rows = PATCH_ROWS, cols = PATCH_COLS;
    const rad = IRIS_RADIUS * DENSITY;
    const kr = Math.ceil(rad);
    const taps = [];
    for (let y = -kr; y <= kr; y++) for (let x2 = -kr; x2 <= kr; x2++) if (x2 * x2 + y * y <= rad * rad) taps.push(y, x2);
    const n = taps.length / 2;
    const inside = new Float64Array(rows * cols);
    for (let r = 0; r < rows; r++) {
      for (let c = 0; c < cols; c++) {
        let s = 0;
        for (let t = 0; t < taps.length; t += 2) {
          s += patch[clampIndex(r + taps[t], rows) * cols + clampIndex(c + taps[t + 1], cols)];
        }
        inside[r * cols + c] = s / n;
      }
    }
    const side = rint(0.6 * rad), tall = rint(1.2 * rad);
    const ax = side >> 1, ay = tall >> 1;
    const box = new Float64Array(rows * cols);
    for (let r = 0; r < rows; r++) {
      for (let c = 0; c < cols; c++) {
        let s = 0;
        for (let y = 0; y < tall; y++) {
          for (let x2 = 0; x2 < side; x2++) s += patch[clampIndex(r + y - ay, rows) * cols + clampIndex(c + x2 - ax, cols)];
        }
        box[r * cols + c] = s / (side * tall);
      }
    }
    const shift = rint(rad + side / 2);
    const beside = new Float64Array(rows * cols);
    for (let r = 0; r < rows; r++) {
      const o = r * cols;
      for (let c = shift; c < cols - shift; c++) beside[o + c] = 0.5 * (box[o + c - shift] + box[o + c + shift]);
      for (let c = 0; c < shift; c++) beside[o + c] = beside[o + shift];
      for (let c = cols - shift; c < cols; c++) beside[o + c] = beside[o + cols - shift - 1];
    }
    const r0 = rowOf(IRIS_V[0]), r1 = rowOf(IRIS_V[1]), c0 = colOf(-IRIS_U), c1 = colOf(IRIS_U);
    const score = (r, c) => inside[r * cols + c] - 0.5 * beside[r * cols + c];
    let best = Infinity, br = r0, bc4 = c0;
    for (let r = r0; r <= r1; r++) {
      for (let c = c0; c <= c1; c++) {
        const s = score(r, c);
        if (s < best) {
          best = s;
          br = r;
          bc4 = c;
        }
      }
    }
    const across = [], down = [];
    for (let c = c0; c <= c1; c++) across.push(score(br, c));
    for (let r = r0; r <= r1; r++) down.push(score(r, bc4));
    return [uOf(c0 + peak(across, bc4 - c0)), vOf(r0 + peak(down, br - r0))];
  }
  var Eye = class {
    /** The eye of `tex` whose ring (8 points, (x, y) px pairs) is `ring`. */
    constructor(tex, ring) {
      const frame = EyeFrame.of(ring);
      this.frame = frame;
      const ew = frame.width;
      let lx = Infinity, ly = Infinity, hx = -Infinity, hy = -Infinity;
      for (const u4 of SPAN_U) {
        for (const v2 of SPAN_V) {
          const [x2, y] = frame.toImage(u4, v2);
          lx = Math.min(lx, x2);
          ly = Math.min(ly, y);
          hx = Math.max(hx, x2);
          hy = Math.max(hy, y);
        }
      }
      const x0 = Math.max(Math.floor(lx), 0), y0 = Math.max(Math.floor(ly), 0);
      const x1 = Math.min(Math.ceil(hx) + 1, tex.width), y1 = Math.min(Math.ceil(hy) + 1, tex.height);
      this.x0 = x0;
      this.y0 = y0;
      this.x1 = x1;
      this.y1 = y1;
      const w = Math.max(x1 - x0, 0), h = Math.max(y1 - y0, 0), n = w * h;
      const region = new Uint8Array(n * 3);
      this.key = new Uint8Array(n * 4);
      for (let y = 0; y < h; y++) {
        const row = tex.rgba.subarray(((y0 + y) * tex.width + x0) * 4, ((y0 + y) * tex.width + x1) * 4);
        this.key.set(row, y * w * 4);
        for (let x2 = 0; x2 < w; x2++) for (let c = 0; c < 3; c++) region[(y * w + x2) * 3 + c] = row[x2 * 4 + c];
      }
      this.irisUv = findIris(eyePatch(tex, frame));
      const centre = frame.toImage(this.irisUv[0], this.irisUv[1]);
      const cx = centre[0] - x0, cy = centre[1] - y0;
      this.radius = IRIS_RADIUS * ew * IRIS_REACH;
      this.disc = new Float64Array(n);
      for (let y = 0; y < h; y++) {
        for (let x2 = 0; x2 < w; x2++) {
          const dx = x2 - cx, dy = y - cy;
          this.disc[y * w + x2] = Math.min(Math.max(this.radius + 0.5 - Math.sqrt(dx * dx + dy * dy), 0), 1);
        }
      }
      const mask = new Uint8Array(n);
      const pts = [];
      for (let k = 0; k < 8; k++) pts.push(rint((ring[2 * k] - x0) * 16), rint((ring[2 * k + 1] - y0) * 16));
      if (n) fillPolyAA({ img: mask, w, h, colour: [255] }, pts, 4);
      this.opening = new Float32Array(n);
      for (let k = 0; k < n; k++) this.opening[k] = Math.fround(mask[k] / 255);
      const inner = erodeEllipse(this.opening, w, h, 2 * Math.max(1, rint(LID_EDGE * ew)) + 1);
      const hole = new Uint8Array(n), inside = new Uint8Array(n);
      let nBeside = 0, nInside = 0;
      for (let k = 0; k < n; k++) {
        this.disc[k] *= inner[k];
        hole[k] = +(this.disc[k] > 0);
        inside[k] = +(inner[k] > 0.5);
        nInside += inside[k];
        nBeside += +(inside[k] && !hole[k]);
      }
      const pick = (k) => nBeside ? inside[k] && !hole[k] : nInside ? inside[k] : 1;
      const grey = [];
      const chosen = [];
      for (let k = 0; k < n; k++) {
        if (!pick(k)) continue;
        chosen.push(k);
        grey.push(region[3 * k] * 0.299 + region[3 * k + 1] * 0.587 + region[3 * k + 2] * 0.114);
      }
      const sclera = [0, 0, 0];
      if (chosen.length) {
        const p75 = percentile(Float64Array.from(grey), 75);
        const bright = chosen.filter((_, m) => grey[m] >= p75);
        for (let c = 0; c < 3; c++) sclera[c] = rint(median(Float64Array.from(bright, (k) => region[3 * k + c])));
      }
      const source = region.slice();
      for (let k = 0; k < n; k++) if (!inside[k]) for (let c = 0; c < 3; c++) source[3 * k + c] = sclera[c];
      const grown = new Uint8Array(n);
      for (let y = 0; y < h; y++) {
        for (let x2 = 0; x2 < w; x2++) {
          let on = 0;
          for (let dy = -1; dy <= 1 && !on; dy++) {
            for (let dx = -1; dx <= 1; dx++) {
              const yy = y + dy, xx = x2 + dx;
              if (yy >= 0 && yy < h && xx >= 0 && xx < w && hole[yy * w + xx]) {
                on = 1;
                break;
              }
            }
          }
          grown[y * w + x2] = on;
        }
      }
      if (n) inpaintTelea(source, grown, w, h, Math.max(2, this.radius / 3));
      const blendSigma = Math.max(1, this.radius / 8), reach = gaussianSize(blendSigma) >> 1;
      let hx0 = w, hy0 = h, hx1 = 0, hy1 = 0;
      for (let k = 0; k < n; k++) {
        if (!hole[k]) continue;
        const x2 = k % w, y = (k - x2) / w;
        hx0 = Math.min(hx0, x2);
        hx1 = Math.max(hx1, x2 + 1);
        hy0 = Math.min(hy0, y);
        hy1 = Math.max(hy1, y + 1);
      }
      const win = [Math.max(hx0 - reach, 0), Math.max(hy0 - reach, 0), Math.min(hx1 + reach, w), Math.min(hy1 + reach, h)];
      const fill = gaussianBlur(Float32Array.from(source), w, h, 3, Math.max(1, this.radius / 4), win);
      const blend = gaussianBlur(Float32Array.from(hole), w, h, 1, blendSigma, win);
      this.iris = Float32Array.from(region);
      this.clean = new Float32Array(n * 3);
      const fr = Math.fround;
      for (let k = 0; k < n; k++) {
        const b = Math.max(fr(blend[k] * this.opening[k]), hole[k]);
        for (let c = 0; c < 3; c++) {
          const i2 = this.iris[3 * k + c];
          this.clean[3 * k + c] = fr(i2 + fr(b * fr(fill[3 * k + c] - i2)));
        }
      }
    }
    /** The warp's offset for an iris shift (u, v) eye widths: texture px (dx, dy) moved, quantised
     * to 1/32 px as facemime.render.bilinear.shift_offset does: each pixel samples the key frame at (x + ox / 32, y + oy / 32);
     * null when the shift is below PASTE_STILL. */
    offset(shift) {
      const a = this.frame.axes;
      const dx = shift[0] * a[0] + shift[1] * a[2], dy = shift[0] * a[1] + shift[1] * a[3];
      if (Math.max(Math.abs(dx), Math.abs(dy)) < PASTE_STILL) return null;
      return [rint(-Math.fround(dx) * 1024) + 16 >> 5, rint(-Math.fround(dy) * 1024) + 16 >> 5];
    }
    /** Paints the eye into `out` (the texture's RGBA working copy, `width` px wide) with the warp
     * offset `off` (offset()), or as on the key frame when null. */
    paint(out, width, off) {
      const { x0, y0, x1, y1 } = this;
      const w = x1 - x0, h = y1 - y0;
      if (w <= 0 || h <= 0) return;
      if (!off) {
        for (let y = 0; y < h; y++) out.set(this.key.subarray(y * w * 4, (y + 1) * w * 4), ((y0 + y) * width + x0) * 4);
        return;
      }
      const sx = off[0] >> 5, sy = off[1] >> 5, fx = (off[0] & 31) / 32, fy = (off[1] & 31) / 32;
      const fr = Math.fround;
      const w00 = fr((1 - fx) * (1 - fy)), w01 = fr(fx * (1 - fy)), w10 = fr((1 - fx) * fy), w11 = fr(fx * fy);
      const { iris, clean, disc, opening } = this;
      for (let y = 0; y < h; y++) {
        const ya = y + sy, yb = ya + 1;
        const ra = clampIndex(ya, h) * w, rb = clampIndex(yb, h) * w;
        const inA = ya >= 0 && ya < h, inB = yb >= 0 && yb < h;
        for (let x2 = 0; x2 < w; x2++) {
          const xa = x2 + sx, xb = xa + 1;
          const ca3 = clampIndex(xa, w), cb = clampIndex(xb, w);
          const inXa = xa >= 0 && xa < w, inXb = xb >= 0 && xb < w;
          const alpha = (w00 * (inA && inXa ? disc[ra + ca3] : 0) + w01 * (inA && inXb ? disc[ra + cb] : 0) + w10 * (inB && inXa ? disc[rb + ca3] : 0) + w11 * (inB && inXb ? disc[rb + cb] : 0)) * opening[y * w + x2];
          const o = ((y0 + y) * width + x0 + x2) * 4, k = (y * w + x2) * 3;
          for (let c = 0; c < 3; c++) {
            const moved = fr(w00 * iris[(ra + ca3) * 3 + c] + w01 * iris[(ra + cb) * 3 + c] + w10 * iris[(rb + ca3) * 3 + c] + w11 * iris[(rb + cb) * 3 + c]);
            const v2 = clean[k + c] + alpha * fr(moved - clean[k + c]) + 0.5;
            out[o + c] = v2 <= 0 ? 0 : v2 >= 255 ? 255 : Math.floor(v2);
          }
        }
      }
    }
  };
  var LookPainter = class {
    /** Finds each eye's iris on `texture` (RGBA) at `model`'s eye rings (groups eye_right and
     * eye_left, 8 vertices each) and prepares the eye with the iris painted out. An eye whose group
     * is missing or malformed is left as on the texture. */
    constructor(texture, model) {
      /** The eyes' warp offsets last painted (Eye.offset, 'still' as on the key frame); null before
       * the first call. */
      this.last = null;
      this.eyes = EYES.map((name) => {
        const ring = model.groups[name];
        if (!ring || ring.length !== 8) return null;
        const px = new Float64Array(16);
        ring.forEach((v2, k) => {
          px[2 * k] = model.uv[2 * v2] * texture.width - 0.5;
          px[2 * k + 1] = model.uv[2 * v2 + 1] * texture.height - 0.5;
        });
        return new Eye(texture, px);
      });
      this.work = { width: texture.width, height: texture.height, rgba: texture.rgba.slice() };
    }
    /** The texture with the irises shifted by `iris` ([[u, v] of the subject's right eye (group
     * eye_right), [u, v] of the left eye (eye_left)], eye widths), or null when it is the same as
     * the last returned one (so the caller need not re-upload; the first call always returns it).
     * The returned Picture is a working copy reused between calls. */
    texture(iris) {
      const offsets = this.eyes.map((eye, k) => eye?.offset(iris[k] ?? [0, 0]) ?? null);
      const key = offsets.map((o) => o ? `${o[0]},${o[1]}` : "still").join(";");
      if (key === this.last) return null;
      this.eyes.forEach((eye, k) => eye?.paint(this.work.rgba, this.work.width, offsets[k]));
      this.last = key;
      return this.work;
    }
  };

  // src/render/mouth.ts
  function teethUncovered(spread) {
    return Math.min(Math.max((spread - TEETH_SPREAD[0]) / (TEETH_SPREAD[1] - TEETH_SPREAD[0]), 0), 1);
  }
  function mouthPatch(upper, lower, uncovered, size) {
    const k = upper.length / 2, kl = lower.length / 2;
    const poly = [];
    for (let i2 = 0; i2 < k; i2++) poly.push(upper[2 * i2], upper[2 * i2 + 1]);
    for (let i2 = kl - 1; i2 >= 0; i2--) poly.push(lower[2 * i2], lower[2 * i2 + 1]);
    let minX = Infinity, minY = Infinity, maxX = -Infinity, maxY = -Infinity;
    for (let i2 = 0; i2 < poly.length; i2 += 2) {
      minX = Math.min(minX, poly[i2]);
      maxX = Math.max(maxX, poly[i2]);
      minY = Math.min(minY, poly[i2 + 1]);
      maxY = Math.max(maxY, poly[i2 + 1]);
    }
    const x0 = Math.max(Math.floor(minX) - 1, 0), y0 = Math.max(Math.floor(minY) - 1, 0);
    const x1 = Math.min(Math.ceil(maxX) + 2, size[0]), y1 = Math.min(Math.ceil(maxY) + 2, size[1]);
    if (x1 - x0 < 2 || y1 - y0 < 2) return null;
    const w = x1 - x0, h = y1 - y0;
    const fix = (pts) => Array.from(pts, (v2, i2) => rint((v2 - (i2 % 2 ? y0 : x0)) * (1 << SHIFT)));
    const mask = new Uint8Array(w * h);
    fillPolyAA({ img: mask, w, h, colour: [255] }, fix(poly), SHIFT);
    if (!mask.some((v2) => v2 > 0)) return null;
    const paint = new Uint8Array(w * h * 3);
    for (let p = 0; p < w * h; p++) paint.set(CAVITY, 3 * p);
    const ax = upper[2 * (k - 1)] - upper[0], ay = upper[2 * (k - 1) + 1] - upper[1];
    const width = Math.hypot(ax, ay);
    const downX = -ay / Math.max(width, 1e-9), downY = ax / Math.max(width, 1e-9);
    const same2 = k === kl;
    let keep = Array.from({ length: k }, (_, i2) => same2 ? Math.abs(k > 1 ? -1 + 2 * i2 / (k - 1) : -1) <= TEETH_SPAN : true);
    if (same2 && keep.filter(Boolean).length < 2) keep = keep.map(() => true);
    const idx = keep.flatMap((kept, i2) => kept ? [i2] : []);
    const opening = idx.map((i2) => {
      const o = same2 ? (lower[2 * i2] - upper[2 * i2]) * downX + (lower[2 * i2 + 1] - upper[2 * i2 + 1]) * downY : width;
      return o * Math.min(Math.max(o / (TEETH_FROM * width) - 1, 0), 1);
    });
    const rows = [
      [upper, UPPER_TEETH, UPPER_SHARE, Math.max(uncovered, UPPER_MIN), 1],
      [lower, LOWER_TEETH, LOWER_SHARE, uncovered, -1]
    ];
    for (const [curve, height, share, shown2, sign] of rows) {
      const reach = opening.map((o) => shown2 * Math.min(height * width, share * o));
      if (Math.max(...reach) < 0.5) continue;
      const edge = idx.flatMap((i2) => [curve[2 * i2], curve[2 * i2 + 1]]);
      const tips = idx.flatMap((_, j) => [edge[2 * j] + sign * reach[j] * downX, edge[2 * j + 1] + sign * reach[j] * downY]);
      const outline = [...edge];
      for (let j = idx.length - 1; j >= 0; j--) outline.push(tips[2 * j], tips[2 * j + 1]);
      fillPolyAA({ img: paint, w, h, colour: TEETH }, fix(outline), SHIFT);
      const gaps = { img: paint, w, h, colour: GAPS };
      for (let j = 1; j < idx.length - 1; j++) {
        lineAAShifted(gaps, fix(edge.slice(2 * j, 2 * j + 2)), fix(tips.slice(2 * j, 2 * j + 2)), SHIFT);
      }
    }
    const centre = (upper[0] + upper[2 * (k - 1)]) / 2, half = Math.max(width / 2, 1);
    const rgba = new Uint8Array(w * h * 4);
    for (let x2 = 0; x2 < w; x2++) {
      const cx = (x0 + x2 - centre) / half;
      const shade = Math.min(Math.max(1.15 - 0.6 * cx * cx, 0.35), 1);
      for (let y = 0; y < h; y++) {
        const p = 4 * (y * w + x2);
        for (let c = 0; c < 3; c++) rgba[p + c] = Math.round(paint[3 * (y * w + x2) + c] * shade);
        rgba[p + 3] = mask[y * w + x2];
      }
    }
    return { x0, y0, width: w, height: h, rgba };
  }

  // src/render/samples.ts
  var MOUTH_GROUPS = ["mouth_outer_upper", "mouth_outer_lower", "mouth_inner_upper", "mouth_inner_lower"];
  function interiorUv(model) {
    const uv = new Float64Array(model.vertices.length / 3 * 2);
    const upper = model.groups.mouth_inner_upper ?? [], lower = model.groups.mouth_inner_lower ?? [];
    for (const [curve, v2] of [[upper, 0], [lower, 1]]) {
      const step = 1 / (curve.length - 1);
      curve.forEach((vertex, i2) => {
        uv[2 * vertex] = curve.length > 1 && i2 === curve.length - 1 ? 1 : i2 * step || 0;
        uv[2 * vertex + 1] = v2;
      });
    }
    for (const vertex of upper) if (lower.includes(vertex)) uv[2 * vertex + 1] = 0.5;
    return uv;
  }
  function roundHalfEven(x2) {
    const f = Math.floor(x2), d = x2 - f;
    return d < 0.5 ? f : d > 0.5 ? f + 1 : f % 2 === 0 ? f : f + 1;
  }
  function sentSamples(kinds, values, first) {
    const extras = Array.from(kinds);
    if (!extras.some((k) => SAMPLE_KINDS.includes(k))) return null;
    return SAMPLE_KINDS.map((kind) => {
      const j = extras.indexOf(kind);
      const k = roundHalfEven(j < 0 ? 0 : values[first + j]);
      return k < 1 ? null : k - 1;
    });
  }
  function weighEyes(key) {
    return Float64Array.from(key, (v2, j) => v2 * (j < 2 ? 1 : IRIS_WEIGHT));
  }
  function pairwiseSum(x2, start, n) {
    if (n < 8) {
      let s = -0;
      for (let i2 = 0; i2 < n; i2++) s += x2[start + i2];
      return s;
    }
    if (n <= 128) {
      const r = [0, 1, 2, 3, 4, 5, 6, 7].map((i3) => x2[start + i3]);
      let i2 = 8;
      for (; i2 < n - n % 8; i2 += 8) for (let j = 0; j < 8; j++) r[j] += x2[start + i2 + j];
      let s = r[0] + r[1] + (r[2] + r[3]) + (r[4] + r[5] + (r[6] + r[7]));
      for (; i2 < n; i2++) s += x2[start + i2];
      return s;
    }
    let n2 = Math.floor(n / 2);
    n2 -= n2 % 8;
    return pairwiseSum(x2, start, n2) + pairwiseSum(x2, start + n2, n - n2);
  }
  function nearest(keys, key) {
    const sq = new Float64Array(key.length);
    let best = -1, bestD = Infinity;
    keys.forEach((k, s) => {
      for (let j = 0; j < key.length; j++) sq[j] = (k[j] - key[j]) * (k[j] - key[j]);
      const d = Math.sqrt(pairwiseSum(sq, 0, key.length));
      if (best < 0 || d < bestD) {
        best = s;
        bestD = d;
      }
    });
    let norm2 = 0;
    for (let j = 0; j < key.length; j++) norm2 += key[j] * key[j];
    return best < 0 || Math.sqrt(norm2) <= bestD ? null : best;
  }
  var SamplePainter = class {
    /** `knots`: the model's knots' vertex indices (Deformer.knots). */
    constructor(groups, model, knots) {
      this.groups = groups;
      this.work = null;
      this.keys = groups.map((g) => g.name === "eyes" ? g.keys.map(weighEyes) : g.keys);
      const lips = new Set(MOUTH_GROUPS.flatMap((name) => model.groups[name] ?? []));
      this.mouth = knots.flatMap((v2, k) => lips.has(v2) ? [2 * k, 2 * k + 1] : []);
    }
    /** Each group's sample for a frame (in the groups' order; null: nothing pasted): the stream's
     * ``sent`` choice (per group of SAMPLE_GROUPS, sentSamples; an index beyond a group's samples
     * draws none), or, where the stream sends none, the sample nearest the frame's shape: `offsets`
     * the knots' (x, y) offsets flattened, the actor's model units; `look` the frame's look vector
     * (closures, then iris u, v of each eye). */
    choose(offsets, look, sent = null) {
      if (sent) {
        return this.groups.map((g) => {
          const k = sent[SAMPLE_GROUPS.indexOf(g.name)] ?? null;
          return k !== null && k < g.keys.length ? k : null;
        });
      }
      const frame = {
        eyes: weighEyes(look),
        mouth: Float64Array.from(this.mouth, (r) => offsets[r])
      };
      return this.groups.map((g, i2) => {
        const key = frame[g.name];
        return this.keys[i2][0].length === key.length ? nearest(this.keys[i2], key) : null;
      });
    }
    /** The chosen mouth sample's interior image (interiorUv), and the sample's index; null where
     * no mouth sample is chosen or it has none. */
    interior(chosen) {
      const i2 = this.groups.findIndex((g) => g.name === "mouth"), k = i2 < 0 ? null : chosen[i2];
      const image = k === null ? null : this.groups[i2].interiors?.[k] ?? null;
      return image && k !== null ? { sample: k, image } : null;
    }
    /** `texture` with the chosen samples pasted (a working copy reused between calls), or
     * `texture` itself when none is chosen. */
    paint(texture, chosen) {
      if (chosen.every((k) => k === null)) return texture;
      if (!this.work || this.work.width !== texture.width || this.work.height !== texture.height) {
        this.work = { width: texture.width, height: texture.height, rgba: texture.rgba.slice() };
      } else {
        this.work.rgba.set(texture.rgba);
      }
      this.groups.forEach((g, i2) => {
        const k = chosen[i2];
        if (k !== null) g.boxes.forEach(([x2, y], b) => pasteFaded(this.work, g.images[k][b], x2, y));
      });
      return this.work;
    }
  };

  // node_modules/robust-predicates/esm/util.js
  var epsilon = 11102230246251565e-32;
  var splitter = 134217729;
  var resulterrbound = (3 + 8 * epsilon) * epsilon;
  function sum(elen, e, flen, f, h) {
    let Q, Qnew, hh, bvirt;
    let enow = e[0];
    let fnow = f[0];
    let eindex = 0;
    let findex = 0;
    if (fnow > enow === fnow > -enow) {
      Q = enow;
      enow = e[++eindex];
    } else {
      Q = fnow;
      fnow = f[++findex];
    }
    let hindex = 0;
    if (eindex < elen && findex < flen) {
      if (fnow > enow === fnow > -enow) {
        Qnew = enow + Q;
        hh = Q - (Qnew - enow);
        enow = e[++eindex];
      } else {
        Qnew = fnow + Q;
        hh = Q - (Qnew - fnow);
        fnow = f[++findex];
      }
      Q = Qnew;
      if (hh !== 0) {
        h[hindex++] = hh;
      }
      while (eindex < elen && findex < flen) {
        if (fnow > enow === fnow > -enow) {
          Qnew = Q + enow;
          bvirt = Qnew - Q;
          hh = Q - (Qnew - bvirt) + (enow - bvirt);
          enow = e[++eindex];
        } else {
          Qnew = Q + fnow;
          bvirt = Qnew - Q;
          hh = Q - (Qnew - bvirt) + (fnow - bvirt);
          fnow = f[++findex];
        }
        Q = Qnew;
        if (hh !== 0) {
          h[hindex++] = hh;
        }
      }
    }
    while (eindex < elen) {
      Qnew = Q + enow;
      bvirt = Qnew - Q;
      hh = Q - (Qnew - bvirt) + (enow - bvirt);
      enow = e[++eindex];
      Q = Qnew;
      if (hh !== 0) {
        h[hindex++] = hh;
      }
    }
    while (findex < flen) {
      Qnew = Q + fnow;
      bvirt = Qnew - Q;
      hh = Q - (Qnew - bvirt) + (fnow - bvirt);
      fnow = f[++findex];
      Q = Qnew;
      if (hh !== 0) {
        h[hindex++] = hh;
      }
    }
    if (Q !== 0 || hindex === 0) {
      h[hindex++] = Q;
    }
    return hindex;
  }
  function estimate(elen, e) {
    let Q = e[0];
    for (let i2 = 1; i2 < elen; i2++) Q += e[i2];
    return Q;
  }
  function vec(n) {
    return new Float64Array(n);
  }

  // node_modules/robust-predicates/esm/orient2d.js
  var ccwerrboundA = (3 + 16 * epsilon) * epsilon;
  var ccwerrboundB = (2 + 12 * epsilon) * epsilon;
  var ccwerrboundC = (9 + 64 * epsilon) * epsilon * epsilon;
  var B = vec(4);
  var C1 = vec(8);
  var C2 = vec(12);
  var D = vec(16);
  var u = vec(4);
  function orient2dadapt(ax, ay, bx, by, cx, cy, detsum) {
    let acxtail, acytail, bcxtail, bcytail;
    let bvirt, c, ahi, alo, bhi, blo, _i, _j, _0, s1, s0, t1, t0, u32;
    const acx = ax - cx;
    const bcx = bx - cx;
    const acy = ay - cy;
    const bcy = by - cy;
    s1 = acx * bcy;
    c = splitter * acx;
    ahi = c - (c - acx);
    alo = acx - ahi;
    c = splitter * bcy;
    bhi = c - (c - bcy);
    blo = bcy - bhi;
    s0 = alo * blo - (s1 - ahi * bhi - alo * bhi - ahi * blo);
    t1 = acy * bcx;
    c = splitter * acy;
    ahi = c - (c - acy);
    alo = acy - ahi;
    c = splitter * bcx;
    bhi = c - (c - bcx);
    blo = bcx - bhi;
    t0 = alo * blo - (t1 - ahi * bhi - alo * bhi - ahi * blo);
    _i = s0 - t0;
    bvirt = s0 - _i;
    B[0] = s0 - (_i + bvirt) + (bvirt - t0);
    _j = s1 + _i;
    bvirt = _j - s1;
    _0 = s1 - (_j - bvirt) + (_i - bvirt);
    _i = _0 - t1;
    bvirt = _0 - _i;
    B[1] = _0 - (_i + bvirt) + (bvirt - t1);
    u32 = _j + _i;
    bvirt = u32 - _j;
    B[2] = _j - (u32 - bvirt) + (_i - bvirt);
    B[3] = u32;
    let det = estimate(4, B);
    let errbound = ccwerrboundB * detsum;
    if (det >= errbound || -det >= errbound) {
      return det;
    }
    bvirt = ax - acx;
    acxtail = ax - (acx + bvirt) + (bvirt - cx);
    bvirt = bx - bcx;
    bcxtail = bx - (bcx + bvirt) + (bvirt - cx);
    bvirt = ay - acy;
    acytail = ay - (acy + bvirt) + (bvirt - cy);
    bvirt = by - bcy;
    bcytail = by - (bcy + bvirt) + (bvirt - cy);
    if (acxtail === 0 && acytail === 0 && bcxtail === 0 && bcytail === 0) {
      return det;
    }
    errbound = ccwerrboundC * detsum + resulterrbound * Math.abs(det);
    det += acx * bcytail + bcy * acxtail - (acy * bcxtail + bcx * acytail);
    if (det >= errbound || -det >= errbound) return det;
    s1 = acxtail * bcy;
    c = splitter * acxtail;
    ahi = c - (c - acxtail);
    alo = acxtail - ahi;
    c = splitter * bcy;
    bhi = c - (c - bcy);
    blo = bcy - bhi;
    s0 = alo * blo - (s1 - ahi * bhi - alo * bhi - ahi * blo);
    t1 = acytail * bcx;
    c = splitter * acytail;
    ahi = c - (c - acytail);
    alo = acytail - ahi;
    c = splitter * bcx;
    bhi = c - (c - bcx);
    blo = bcx - bhi;
    t0 = alo * blo - (t1 - ahi * bhi - alo * bhi - ahi * blo);
    _i = s0 - t0;
    bvirt = s0 - _i;
    u[0] = s0 - (_i + bvirt) + (bvirt - t0);
    _j = s1 + _i;
    bvirt = _j - s1;
    _0 = s1 - (_j - bvirt) + (_i - bvirt);
    _i = _0 - t1;
    bvirt = _0 - _i;
    u[1] = _0 - (_i + bvirt) + (bvirt - t1);
    u32 = _j + _i;
    bvirt = u32 - _j;
    u[2] = _j - (u32 - bvirt) + (_i - bvirt);
    u[3] = u32;
    const C1len = sum(4, B, 4, u, C1);
    s1 = acx * bcytail;
    c = splitter * acx;
    ahi = c - (c - acx);
    alo = acx - ahi;
    c = splitter * bcytail;
    bhi = c - (c - bcytail);
    blo = bcytail - bhi;
    s0 = alo * blo - (s1 - ahi * bhi - alo * bhi - ahi * blo);
    t1 = acy * bcxtail;
    c = splitter * acy;
    ahi = c - (c - acy);
    alo = acy - ahi;
    c = splitter * bcxtail;
    bhi = c - (c - bcxtail);
    blo = bcxtail - bhi;
    t0 = alo * blo - (t1 - ahi * bhi - alo * bhi - ahi * blo);
    _i = s0 - t0;
    bvirt = s0 - _i;
    u[0] = s0 - (_i + bvirt) + (bvirt - t0);
    _j = s1 + _i;
    bvirt = _j - s1;
    _0 = s1 - (_j - bvirt) + (_i - bvirt);
    _i = _0 - t1;
    bvirt = _0 - _i;
    u[1] = _0 - (_i + bvirt) + (bvirt - t1);
    u32 = _j + _i;
    bvirt = u32 - _j;
    u[2] = _j - (u32 - bvirt) + (_i - bvirt);
    u[3] = u32;
    const C2len = sum(C1len, C1, 4, u, C2);
    s1 = acxtail * bcytail;
    c = splitter * acxtail;
    ahi = c - (c - acxtail);
    alo = acxtail - ahi;
    c = splitter * bcytail;
    bhi = c - (c - bcytail);
    blo = bcytail - bhi;
    s0 = alo * blo - (s1 - ahi * bhi - alo * bhi - ahi * blo);
    t1 = acytail * bcxtail;
    c = splitter * acytail;
    ahi = c - (c - acytail);
    alo = acytail - ahi;
    c = splitter * bcxtail;
    bhi = c - (c - bcxtail);
    blo = bcxtail - bhi;
    t0 = alo * blo - (t1 - ahi * bhi - alo * bhi - ahi * blo);
    _i = s0 - t0;
    bvirt = s0 - _i;
    u[0] = s0 - (_i + bvirt) + (bvirt - t0);
    _j = s1 + _i;
    bvirt = _j - s1;
    _0 = s1 - (_j - bvirt) + (_i - bvirt);
    _i = _0 - t1;
    bvirt = _0 - _i;
    u[1] = _0 - (_i + bvirt) + (bvirt - t1);
    u32 = _j + _i;
    bvirt = u32 - _j;
    u[2] = _j - (u32 - bvirt) + (_i - bvirt);
    u[3] = u32;
    const Dlen = sum(C2len, C2, 4, u, D);
    return D[Dlen - 1];
  }
  function orient2d(ax, ay, bx, by, cx, cy) {
    const detleft = (ay - cy) * (bx - cx);
    const detright = (ax - cx) * (by - cy);
    const det = detleft - detright;
    const detsum = Math.abs(detleft + detright);
    if (Math.abs(det) >= ccwerrboundA * detsum) return det;
    return -orient2dadapt(ax, ay, bx, by, cx, cy, detsum);
  }

  // node_modules/robust-predicates/esm/orient3d.js
  var o3derrboundA = (7 + 56 * epsilon) * epsilon;
  var o3derrboundB = (3 + 28 * epsilon) * epsilon;
  var o3derrboundC = (26 + 288 * epsilon) * epsilon * epsilon;
  var bc = vec(4);
  var ca = vec(4);
  var ab = vec(4);
  var at_b = vec(4);
  var at_c = vec(4);
  var bt_c = vec(4);
  var bt_a = vec(4);
  var ct_a = vec(4);
  var ct_b = vec(4);
  var bct = vec(8);
  var cat = vec(8);
  var abt = vec(8);
  var u2 = vec(4);
  var _8 = vec(8);
  var _8b = vec(8);
  var _16 = vec(16);
  var _12 = vec(12);
  var fin = vec(192);
  var fin2 = vec(192);

  // node_modules/robust-predicates/esm/incircle.js
  var iccerrboundA = (10 + 96 * epsilon) * epsilon;
  var iccerrboundB = (4 + 48 * epsilon) * epsilon;
  var iccerrboundC = (44 + 576 * epsilon) * epsilon * epsilon;
  var bc2 = vec(4);
  var ca2 = vec(4);
  var ab2 = vec(4);
  var aa = vec(4);
  var bb = vec(4);
  var cc = vec(4);
  var u3 = vec(4);
  var v = vec(4);
  var axtbc = vec(8);
  var aytbc = vec(8);
  var bxtca = vec(8);
  var bytca = vec(8);
  var cxtab = vec(8);
  var cytab = vec(8);
  var abt2 = vec(8);
  var bct2 = vec(8);
  var cat2 = vec(8);
  var abtt = vec(4);
  var bctt = vec(4);
  var catt = vec(4);
  var _82 = vec(8);
  var _162 = vec(16);
  var _16b = vec(16);
  var _16c = vec(16);
  var _32 = vec(32);
  var _32b = vec(32);
  var _48 = vec(48);
  var _64 = vec(64);
  var fin3 = vec(1152);
  var fin22 = vec(1152);

  // node_modules/robust-predicates/esm/insphere.js
  var isperrboundA = (16 + 224 * epsilon) * epsilon;
  var isperrboundB = (5 + 72 * epsilon) * epsilon;
  var isperrboundC = (71 + 1408 * epsilon) * epsilon * epsilon;
  var ab3 = vec(4);
  var bc3 = vec(4);
  var cd = vec(4);
  var de = vec(4);
  var ea = vec(4);
  var ac = vec(4);
  var bd = vec(4);
  var ce = vec(4);
  var da = vec(4);
  var eb = vec(4);
  var abc = vec(24);
  var bcd = vec(24);
  var cde = vec(24);
  var dea = vec(24);
  var eab = vec(24);
  var abd = vec(24);
  var bce = vec(24);
  var cda = vec(24);
  var deb = vec(24);
  var eac = vec(24);
  var adet = vec(1152);
  var bdet = vec(1152);
  var cdet = vec(1152);
  var ddet = vec(1152);
  var edet = vec(1152);
  var abdet = vec(2304);
  var cddet = vec(2304);
  var cdedet = vec(3456);
  var deter = vec(5760);
  var _83 = vec(8);
  var _8b2 = vec(8);
  var _8c = vec(8);
  var _163 = vec(16);
  var _24 = vec(24);
  var _482 = vec(48);
  var _48b = vec(48);
  var _96 = vec(96);
  var _192 = vec(192);
  var _384x = vec(384);
  var _384y = vec(384);
  var _384z = vec(384);
  var _768 = vec(768);
  var xdet = vec(96);
  var ydet = vec(96);
  var zdet = vec(96);
  var fin4 = vec(1152);

  // node_modules/delaunator/index.js
  var EPSILON = Math.pow(2, -52);
  var EDGE_STACK = new Uint32Array(512);
  var Delaunator = class _Delaunator {
    /**
     * Constructs a delaunay triangulation object given an array of points (`[x, y]` by default).
     * `getX` and `getY` are optional functions of the form `(point) => value` for custom point formats.
     *
     * @template P
     * @param {P[]} points
     * @param {(p: P) => number} [getX]
     * @param {(p: P) => number} [getY]
     */
    // @ts-expect-error TS2322
    static from(points, getX = defaultGetX, getY = defaultGetY) {
      const n = points.length;
      const coords = new Float64Array(n * 2);
      for (let i2 = 0; i2 < n; i2++) {
        const p = points[i2];
        coords[2 * i2] = getX(p);
        coords[2 * i2 + 1] = getY(p);
      }
      return new _Delaunator(coords);
    }
    /**
     * Constructs a delaunay triangulation object given an array of point coordinates of the form:
     * `[x0, y0, x1, y1, ...]` (use a typed array for best performance). Duplicate points are skipped.
     *
     * @param {T} coords
     */
    constructor(coords) {
      const n = coords.length >> 1;
      if (n > 0 && typeof coords[0] !== "number") throw new Error("Expected coords to contain numbers.");
      this.coords = coords;
      const maxTriangles = Math.max(2 * n - 5, 0);
      this._triangles = new Uint32Array(maxTriangles * 3);
      this._halfedges = new Int32Array(maxTriangles * 3);
      this._hashSize = Math.ceil(Math.sqrt(n));
      this._hullPrev = new Uint32Array(n);
      this._hullNext = new Uint32Array(n);
      this._hullTri = new Uint32Array(n);
      this._hullHash = new Int32Array(this._hashSize);
      this._ids = new Uint32Array(n);
      this._dists = new Float64Array(n);
      this.trianglesLen = 0;
      this._cx = 0;
      this._cy = 0;
      this._hullStart = 0;
      this.hull = this._triangles;
      this.triangles = this._triangles;
      this.halfedges = this._halfedges;
      this.update();
    }
    /**
     * Updates the triangulation if you modified `delaunay.coords` values in place, avoiding expensive memory allocations.
     * Useful for iterative relaxation algorithms such as Lloyd's.
     */
    update() {
      const { coords, _hullPrev: hullPrev, _hullNext: hullNext, _hullTri: hullTri, _hullHash: hullHash } = this;
      const n = coords.length >> 1;
      let minX = Infinity;
      let minY = Infinity;
      let maxX = -Infinity;
      let maxY = -Infinity;
      for (let i3 = 0; i3 < n; i3++) {
        const x2 = coords[2 * i3];
        const y = coords[2 * i3 + 1];
        if (x2 < minX) minX = x2;
        if (y < minY) minY = y;
        if (x2 > maxX) maxX = x2;
        if (y > maxY) maxY = y;
        this._ids[i3] = i3;
      }
      const cx = (minX + maxX) / 2;
      const cy = (minY + maxY) / 2;
      let i0 = 0, i1 = 0, i2 = 0;
      for (let i3 = 0, minDist = Infinity; i3 < n; i3++) {
        const d = dist(cx, cy, coords[2 * i3], coords[2 * i3 + 1]);
        if (d < minDist) {
          i0 = i3;
          minDist = d;
        }
      }
      const i0x = coords[2 * i0];
      const i0y = coords[2 * i0 + 1];
      for (let i3 = 0, minDist = Infinity; i3 < n; i3++) {
        if (i3 === i0) continue;
        const d = dist(i0x, i0y, coords[2 * i3], coords[2 * i3 + 1]);
        if (d < minDist && d > 0) {
          i1 = i3;
          minDist = d;
        }
      }
      let i1x = coords[2 * i1];
      let i1y = coords[2 * i1 + 1];
      let minRadius = Infinity;
      for (let i3 = 0; i3 < n; i3++) {
        if (i3 === i0 || i3 === i1) continue;
        const r = circumradius(i0x, i0y, i1x, i1y, coords[2 * i3], coords[2 * i3 + 1]);
        if (r < minRadius) {
          i2 = i3;
          minRadius = r;
        }
      }
      let i2x = coords[2 * i2];
      let i2y = coords[2 * i2 + 1];
      if (minRadius === Infinity) {
        for (let i3 = 0; i3 < n; i3++) {
          this._dists[i3] = coords[2 * i3] - coords[0] || coords[2 * i3 + 1] - coords[1];
        }
        quicksort(this._ids, this._dists, 0, n - 1);
        const hull = new Uint32Array(n);
        let j = 0;
        for (let i3 = 0, d0 = -Infinity; i3 < n; i3++) {
          const id = this._ids[i3];
          const d = this._dists[id];
          if (d > d0) {
            hull[j++] = id;
            d0 = d;
          }
        }
        this.hull = hull.subarray(0, j);
        this.triangles = new Uint32Array(0);
        this.halfedges = new Int32Array(0);
        return;
      }
      if (orient2d(i0x, i0y, i1x, i1y, i2x, i2y) < 0) {
        const i3 = i1;
        const x2 = i1x;
        const y = i1y;
        i1 = i2;
        i1x = i2x;
        i1y = i2y;
        i2 = i3;
        i2x = x2;
        i2y = y;
      }
      const center = circumcenter(i0x, i0y, i1x, i1y, i2x, i2y);
      this._cx = center.x;
      this._cy = center.y;
      for (let i3 = 0; i3 < n; i3++) {
        this._dists[i3] = dist(coords[2 * i3], coords[2 * i3 + 1], center.x, center.y);
      }
      quicksort(this._ids, this._dists, 0, n - 1);
      this._hullStart = i0;
      let hullSize = 3;
      hullNext[i0] = hullPrev[i2] = i1;
      hullNext[i1] = hullPrev[i0] = i2;
      hullNext[i2] = hullPrev[i1] = i0;
      hullTri[i0] = 0;
      hullTri[i1] = 1;
      hullTri[i2] = 2;
      hullHash.fill(-1);
      hullHash[this._hashKey(i0x, i0y)] = i0;
      hullHash[this._hashKey(i1x, i1y)] = i1;
      hullHash[this._hashKey(i2x, i2y)] = i2;
      this.trianglesLen = 0;
      this._addTriangle(i0, i1, i2, -1, -1, -1);
      for (let k = 0, xp = 0, yp = 0; k < this._ids.length; k++) {
        const i3 = this._ids[k];
        const x2 = coords[2 * i3];
        const y = coords[2 * i3 + 1];
        if (k > 0 && Math.abs(x2 - xp) <= EPSILON && Math.abs(y - yp) <= EPSILON) continue;
        xp = x2;
        yp = y;
        if (i3 === i0 || i3 === i1 || i3 === i2) continue;
        let start = 0;
        for (let j = 0, key = this._hashKey(x2, y); j < this._hashSize; j++) {
          start = hullHash[(key + j) % this._hashSize];
          if (start !== -1 && start !== hullNext[start]) break;
        }
        start = hullPrev[start];
        let e = start, q;
        while (q = hullNext[e], orient2d(x2, y, coords[2 * e], coords[2 * e + 1], coords[2 * q], coords[2 * q + 1]) >= 0) {
          e = q;
          if (e === start) {
            e = -1;
            break;
          }
        }
        if (e === -1) continue;
        let t = this._addTriangle(e, i3, hullNext[e], -1, -1, hullTri[e]);
        hullTri[i3] = this._legalize(t + 2);
        hullTri[e] = t;
        hullSize++;
        let n2 = hullNext[e];
        while (q = hullNext[n2], orient2d(x2, y, coords[2 * n2], coords[2 * n2 + 1], coords[2 * q], coords[2 * q + 1]) < 0) {
          t = this._addTriangle(n2, i3, q, hullTri[i3], -1, hullTri[n2]);
          hullTri[i3] = this._legalize(t + 2);
          hullNext[n2] = n2;
          hullSize--;
          n2 = q;
        }
        if (e === start) {
          while (q = hullPrev[e], orient2d(x2, y, coords[2 * q], coords[2 * q + 1], coords[2 * e], coords[2 * e + 1]) < 0) {
            t = this._addTriangle(q, i3, e, -1, hullTri[e], hullTri[q]);
            this._legalize(t + 2);
            hullTri[q] = t;
            hullNext[e] = e;
            hullSize--;
            e = q;
          }
        }
        this._hullStart = hullPrev[i3] = e;
        hullNext[e] = hullPrev[n2] = i3;
        hullNext[i3] = n2;
        hullHash[this._hashKey(x2, y)] = i3;
        hullHash[this._hashKey(coords[2 * e], coords[2 * e + 1])] = e;
      }
      this.hull = new Uint32Array(hullSize);
      for (let i3 = 0, e = this._hullStart; i3 < hullSize; i3++) {
        this.hull[i3] = e;
        e = hullNext[e];
      }
      this.triangles = this._triangles.subarray(0, this.trianglesLen);
      this.halfedges = this._halfedges.subarray(0, this.trianglesLen);
    }
    /**
     * Calculate an angle-based key for the edge hash used for advancing convex hull.
     *
     * @param {number} x
     * @param {number} y
     * @private
     */
    _hashKey(x2, y) {
      return Math.floor(pseudoAngle(x2 - this._cx, y - this._cy) * this._hashSize) % this._hashSize;
    }
    /**
     * Flip an edge in a pair of triangles if it doesn't satisfy the Delaunay condition.
     *
     * @param {number} a
     * @private
     */
    _legalize(a) {
      const { _triangles: triangles, _halfedges: halfedges, coords } = this;
      let i2 = 0;
      let ar = 0;
      while (true) {
        const b = halfedges[a];
        const a0 = a - a % 3;
        ar = a0 + (a + 2) % 3;
        if (b === -1) {
          if (i2 === 0) break;
          a = EDGE_STACK[--i2];
          continue;
        }
        const b0 = b - b % 3;
        const al = a0 + (a + 1) % 3;
        const bl = b0 + (b + 2) % 3;
        const p0 = triangles[ar];
        const pr = triangles[a];
        const pl = triangles[al];
        const p1 = triangles[bl];
        const illegal = inCircle(
          coords[2 * p0],
          coords[2 * p0 + 1],
          coords[2 * pr],
          coords[2 * pr + 1],
          coords[2 * pl],
          coords[2 * pl + 1],
          coords[2 * p1],
          coords[2 * p1 + 1]
        );
        if (illegal) {
          triangles[a] = p1;
          triangles[b] = p0;
          const hbl = halfedges[bl];
          if (hbl === -1) {
            let e = this._hullStart;
            do {
              if (this._hullTri[e] === bl) {
                this._hullTri[e] = a;
                break;
              }
              e = this._hullPrev[e];
            } while (e !== this._hullStart);
          }
          this._link(a, hbl);
          this._link(b, halfedges[ar]);
          this._link(ar, bl);
          const br = b0 + (b + 1) % 3;
          if (i2 < EDGE_STACK.length) {
            EDGE_STACK[i2++] = br;
          }
        } else {
          if (i2 === 0) break;
          a = EDGE_STACK[--i2];
        }
      }
      return ar;
    }
    /**
     * Link two half-edges to each other.
     * @param {number} a
     * @param {number} b
     * @private
     */
    _link(a, b) {
      this._halfedges[a] = b;
      if (b !== -1) this._halfedges[b] = a;
    }
    /**
     * Add a new triangle given vertex indices and adjacent half-edge ids.
     *
     * @param {number} i0
     * @param {number} i1
     * @param {number} i2
     * @param {number} a
     * @param {number} b
     * @param {number} c
     * @private
     */
    _addTriangle(i0, i1, i2, a, b, c) {
      const t = this.trianglesLen;
      this._triangles[t] = i0;
      this._triangles[t + 1] = i1;
      this._triangles[t + 2] = i2;
      this._link(t, a);
      this._link(t + 1, b);
      this._link(t + 2, c);
      this.trianglesLen += 3;
      return t;
    }
  };
  function pseudoAngle(dx, dy) {
    const p = dx / (Math.abs(dx) + Math.abs(dy));
    return (dy > 0 ? 3 - p : 1 + p) / 4;
  }
  function dist(ax, ay, bx, by) {
    const dx = ax - bx;
    const dy = ay - by;
    return dx * dx + dy * dy;
  }
  function inCircle(ax, ay, bx, by, cx, cy, px, py) {
    const dx = ax - px;
    const dy = ay - py;
    const ex = bx - px;
    const ey = by - py;
    const fx = cx - px;
    const fy = cy - py;
    const ap = dx * dx + dy * dy;
    const bp = ex * ex + ey * ey;
    const cp = fx * fx + fy * fy;
    return dx * (ey * cp - bp * fy) - dy * (ex * cp - bp * fx) + ap * (ex * fy - ey * fx) < 0;
  }
  function circumradius(ax, ay, bx, by, cx, cy) {
    const dx = bx - ax;
    const dy = by - ay;
    const ex = cx - ax;
    const ey = cy - ay;
    const bl = dx * dx + dy * dy;
    const cl = ex * ex + ey * ey;
    const d = 0.5 / (dx * ey - dy * ex);
    const x2 = (ey * bl - dy * cl) * d;
    const y = (dx * cl - ex * bl) * d;
    return x2 * x2 + y * y;
  }
  function circumcenter(ax, ay, bx, by, cx, cy) {
    const dx = bx - ax;
    const dy = by - ay;
    const ex = cx - ax;
    const ey = cy - ay;
    const bl = dx * dx + dy * dy;
    const cl = ex * ex + ey * ey;
    const d = 0.5 / (dx * ey - dy * ex);
    const x2 = ax + (ey * bl - dy * cl) * d;
    const y = ay + (dx * cl - ex * bl) * d;
    return { x: x2, y };
  }
  function quicksort(ids, dists, left, right) {
    if (right - left <= 20) {
      for (let i2 = left + 1; i2 <= right; i2++) {
        const temp = ids[i2];
        const tempDist = dists[temp];
        let j = i2 - 1;
        while (j >= left && dists[ids[j]] > tempDist) ids[j + 1] = ids[j--];
        ids[j + 1] = temp;
      }
    } else {
      const median3 = left + right >> 1;
      let i2 = left + 1;
      let j = right;
      swap(ids, median3, i2);
      if (dists[ids[left]] > dists[ids[right]]) swap(ids, left, right);
      if (dists[ids[i2]] > dists[ids[right]]) swap(ids, i2, right);
      if (dists[ids[left]] > dists[ids[i2]]) swap(ids, left, i2);
      const temp = ids[i2];
      const tempDist = dists[temp];
      while (true) {
        do
          i2++;
        while (dists[ids[i2]] < tempDist);
        do
          j--;
        while (dists[ids[j]] > tempDist);
        if (j < i2) break;
        swap(ids, i2, j);
      }
      ids[left + 1] = ids[j];
      ids[j] = temp;
      if (right - i2 + 1 >= j - left) {
        quicksort(ids, dists, i2, right);
        quicksort(ids, dists, left, j - 1);
      } else {
        quicksort(ids, dists, left, j - 1);
        quicksort(ids, dists, i2, right);
      }
    }
  }
  function swap(arr, i2, j) {
    const tmp = arr[i2];
    arr[i2] = arr[j];
    arr[j] = tmp;
  }
  function defaultGetX(p) {
    return p[0];
  }
  function defaultGetY(p) {
    return p[1];
  }

  // src/render/scene.ts
  var SceneMesh = class {
    constructor(width, height, anchors, outline) {
      this.width = width;
      this.height = height;
      this.anchors = anchors;
      const a = outline.length / 2;
      let cx = 0, cy = 0;
      for (let i2 = 0; i2 < a; i2++) {
        cx += outline[2 * i2];
        cy += outline[2 * i2 + 1];
      }
      cx /= a;
      cy /= a;
      const margin = EDGE_MARGIN * Math.min(width, height);
      const pts = Array.from(outline);
      const follow = new Array(a).fill(1);
      for (const [reach, share] of RINGS) {
        for (let i2 = 0; i2 < a; i2++) {
          const x2 = cx + reach * (outline[2 * i2] - cx), y = cy + reach * (outline[2 * i2 + 1] - cy);
          if (x2 > -0.5 + margin && x2 < width - 0.5 - margin && y > -0.5 + margin && y < height - 0.5 - margin) {
            pts.push(x2, y);
            follow.push(share);
          }
        }
      }
      const lo = [-0.5, -0.5], hi = [width - 0.5, height - 0.5];
      const corners = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
      for (let c = 0; c < 4; c++) {
        const p = corners[c], q = corners[(c + 1) % 4];
        for (let s = 0; s < BORDER_STEPS - 1; s++) {
          const t = s / (BORDER_STEPS - 1);
          pts.push(p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]));
          follow.push(0);
        }
      }
      this.rest = Float64Array.from(pts);
      this.follow = Float64Array.from(follow);
      this.triangles = Uint32Array.from(new Delaunator(this.rest).triangles);
    }
    /** Every vertex now (N*2 px) for the face outline now at ``outline`` (A*2 px). */
    points(outline) {
      const a = this.anchors.length, n = this.rest.length / 2;
      const m = similarity(this.rest.subarray(0, 2 * a), outline);
      const out = new Float64Array(2 * n);
      for (let i2 = 0; i2 < n; i2++) {
        const x2 = this.rest[2 * i2], y = this.rest[2 * i2 + 1], f = this.follow[i2];
        const mx = m[0] * x2 + m[1] * y + m[2], my = m[3] * x2 + m[4] * y + m[5];
        out[2 * i2] = i2 < a ? outline[2 * i2] : Math.min(Math.max(x2 + f * (mx - x2), -0.5), this.width - 0.5);
        out[2 * i2 + 1] = i2 < a ? outline[2 * i2 + 1] : Math.min(Math.max(y + f * (my - y), -0.5), this.height - 0.5);
      }
      return out;
    }
  };
  function similarity(src, dst) {
    const n = src.length / 2;
    let sx = 0, sy = 0, dx = 0, dy = 0;
    for (let i2 = 0; i2 < n; i2++) {
      sx += src[2 * i2];
      sy += src[2 * i2 + 1];
      dx += dst[2 * i2];
      dy += dst[2 * i2 + 1];
    }
    sx /= n;
    sy /= n;
    dx /= n;
    dy /= n;
    let dot = 0, cross = 0, norm = 0;
    for (let i2 = 0; i2 < n; i2++) {
      const px = src[2 * i2] - sx, py = src[2 * i2 + 1] - sy, qx = dst[2 * i2] - dx, qy = dst[2 * i2 + 1] - dy;
      dot += px * qx + py * qy;
      cross += px * qy - py * qx;
      norm += px * px + py * py;
    }
    const a = norm > 0 ? dot / norm : 1, b = norm > 0 ? cross / norm : 0;
    return [a, -b, dx - a * sx + b * sy, b, a, dy - b * sx - a * sy];
  }

  // src/render/synth.ts
  var Synthesizer = class {
    constructor(renderer2, actor, header) {
      this.renderer = renderer2;
      this.actor = actor;
      this.header = header;
      /** The texture the look painted last (LookPainter.texture), the samples pasted into it. */
      this.looked = null;
      /** The samples chosen in the texture uploaded last (SamplePainter.choose, joined). */
      this.pasted = "";
      /** The mouth samples' interiors uploaded so far, by sample index. */
      this.interiors = /* @__PURE__ */ new Map();
      const m = actor.model;
      this.deformer = new Deformer(m);
      if (header.basisLength !== 2 * this.deformer.knots.length) {
        throw new Error(`the stream's basis does not fit the ${this.deformer.knots.length} knots of its actor`);
      }
      this.basis = Float64Array.from(header.basis, (x2) => x2 / BASIS_ONE);
      this.key = poseFromValues(header.references.slice(0, 6).map((r, i2) => r * header.steps[i2]));
      this.restWidth = mouthWidth(m, m.vertices);
      this.textureLayer = renderer2.upload(actor.texture);
      this.painter = new LookPainter(actor.texture, m);
      this.samples = actor.samples ? new SamplePainter(actor.samples, m, this.deformer.knots) : null;
      this.interiorUv = interiorUv(m);
      this.strip = lipStrip(m);
      if (actor.scene) {
        const { width, height } = actor.source;
        const outline = m.groups.face_outline;
        const projected = project(m.vertices, actor.pose).points;
        this.scene = new SceneMesh(width, height, outline, Float64Array.from(outline.flatMap((i2) => [projected[2 * i2], projected[2 * i2 + 1]])));
        this.sceneLayer = renderer2.upload(actor.scene);
        this.sceneUv = Float32Array.from(this.scene.rest, (p, i2) => (p + 0.5) / (i2 % 2 ? height : width));
      } else {
        this.scene = this.sceneLayer = this.sceneUv = null;
      }
    }
    /** The picture's size, px: the scene's, or the stream's when the actor has none. */
    get size() {
      return this.scene ? [this.scene.width, this.scene.height] : [this.header.width, this.header.height];
    }
    /** Replaces the actor's texture (after an appearance update); same size. Its irises are found
     * again, as the Python synthesis does (a few hundred ms for a large texture). */
    retexture(texture) {
      this.painter = new LookPainter(texture, this.actor.model);
    }
    /** Draws ``motion`` into the renderer's canvas, letterboxed into ``view`` ([x, y, w, h]). */
    draw(motion, view) {
      const v2 = motion.values, m = this.actor.model, knots = this.deformer.knots.length;
      const coefficients = this.basis.length / (2 * knots);
      const offsets = new Float64Array(2 * knots);
      for (let c = 0; c < coefficients; c++) {
        const q = v2[6 + c];
        for (let r2 = 0; r2 < 2 * knots; r2++) offsets[r2] += this.basis[c * 2 * knots + r2] * q;
      }
      const look = this.look(v2, 6 + coefficients);
      let vertices = this.deformer.sealed(this.deformer.vertices(offsets), SEAL);
      vertices = closeLids(m, vertices, look.closure);
      const pose = shownPose(poseFromValues(v2), this.actor.pose, this.key, this.scene !== null);
      const { points, depth } = project(vertices, pose);
      const [w, h] = this.size;
      const pick = (name) => Float64Array.from(m.groups[name].flatMap((i2) => [points[2 * i2], points[2 * i2 + 1]]));
      const spread = mouthWidth(m, vertices) / Math.max(this.restWidth, 1e-9);
      const chosen = this.samples?.choose(
        offsets,
        [...look.closure, ...look.iris[0], ...look.iris[1]],
        sentSamples(this.header.extras, v2, 6 + coefficients)
      ) ?? [];
      const interior = this.samples?.interior(chosen) ?? null;
      const patch = interior ? null : mouthPatch(pick("mouth_inner_upper"), pick("mouth_inner_lower"), teethUncovered(spread), [w, h]);
      const eyesChosen = (chosen[SAMPLE_GROUPS.indexOf("eyes")] ?? null) !== null;
      this.uploadTexture(chosen, eyesChosen ? [[0, 0], [0, 0]] : look.iris);
      const r = this.renderer;
      r.begin(w, h, BACKGROUND, view);
      if (this.scene && this.sceneLayer && this.sceneUv) {
        const at = this.scene.points(pick("face_outline"));
        const rest = this.scene.rest, tris = this.scene.triangles;
        const slow = [], fast = [];
        for (let t = 0; t < tris.length; t += 3) {
          let moved = 0;
          for (let c = 0; c < 3; c++) {
            const i2 = tris[t + c];
            moved = Math.max(moved, Math.abs(at[2 * i2] - rest[2 * i2]), Math.abs(at[2 * i2 + 1] - rest[2 * i2 + 1]));
          }
          (moved < SLOW ? slow : fast).push(tris[t], tris[t + 1], tris[t + 2]);
        }
        r.mesh(this.sceneLayer, at, this.sceneUv, Uint32Array.from(slow), false, false);
        r.mesh(this.sceneLayer, at, this.sceneUv, Uint32Array.from(fast), true, false);
      }
      if (interior) {
        let layer = this.interiors.get(interior.sample);
        if (!layer) this.interiors.set(interior.sample, layer = r.upload(interior.image));
        r.mesh(layer, points, this.interiorUv, paintersOrder(points, depth, this.strip, false), true, false);
      } else if (patch) {
        r.mouthPatch(patch);
      }
      r.mesh(this.textureLayer, points, m.uv, paintersOrder(points, depth, m.triangles), true, false);
      if (!motion.face) r.dim(NO_FACE_DIM, w, h);
    }
    /** Uploads the frame's texture when it differs from the last uploaded: the look's irises
     * painted (LookPainter.texture), then the ``chosen`` samples pasted (SamplePainter.choose;
     * facemime.animate.synth.Puppet.render, the stream's own actor: offsets in its model units, no
     * gain). */
    uploadTexture(chosen, iris) {
      const painted = this.painter.texture(iris);
      if (painted) this.looked = painted;
      const looked = this.looked;
      if (!this.samples) {
        if (painted) this.textureLayer = this.renderer.upload(painted, this.textureLayer);
        return;
      }
      const pasted = chosen.join(",");
      if (!painted && pasted === this.pasted) return;
      this.pasted = pasted;
      this.textureLayer = this.renderer.upload(this.samples.paint(looked, chosen), this.textureLayer);
    }
    look(v2, first) {
      const at = (name) => {
        const j = this.header.extras.indexOf(LOOK_NAMES.indexOf(name) + 1);
        return j < 0 ? 0 : v2[first + j];
      };
      return {
        closure: [at("eye_right_closure"), at("eye_left_closure")],
        iris: [[at("iris_right_u"), at("iris_right_v")], [at("iris_left_u"), at("iris_left_v")]]
      };
    }
  };
  function paintersOrder(points, depth, triangles, cull = true) {
    const order = [];
    for (let f = 0; f < triangles.length / 3; f++) {
      const a = triangles[3 * f], b = triangles[3 * f + 1], c = triangles[3 * f + 2];
      const area2 = (points[2 * b] - points[2 * a]) * (points[2 * c + 1] - points[2 * a + 1]) - (points[2 * b + 1] - points[2 * a + 1]) * (points[2 * c] - points[2 * a]);
      if (cull ? area2 < 0 : area2 !== 0) order.push([(depth[a] + depth[b] + depth[c]) / 3, f]);
    }
    order.sort((x2, y) => x2[0] - y[0]);
    const out = new Uint32Array(order.length * 3);
    order.forEach(([, f], i2) => out.set(triangles.subarray(3 * f, 3 * f + 3), 3 * i2));
    return out;
  }

  // src/stream/crc32.ts
  var TABLE = (() => {
    const t = new Uint32Array(256);
    for (let n = 0; n < 256; n++) {
      let c = n;
      for (let k = 0; k < 8; k++) c = c & 1 ? 3988292384 ^ c >>> 1 : c >>> 1;
      t[n] = c >>> 0;
    }
    return t;
  })();
  function crc32(bytes, start = 0, end = bytes.length) {
    let c = 4294967295;
    for (let i2 = start; i2 < end; i2++) c = TABLE[(c ^ bytes[i2]) & 255] ^ c >>> 8;
    return (c ^ 4294967295) >>> 0;
  }

  // src/stream/chunks.ts
  var KIND_HEADER = 1;
  var KIND_ACTOR = 2;
  var KIND_INTRA = 3;
  var KIND_INTER = 4;
  var KIND_APPEARANCE = 5;
  var APPEARANCE_PREFIX = 8;
  var MAX_PAYLOAD = [0, 1 << 20, 1 << 26, 1 << 16, 1 << 16, 1 << 20];
  function maxPayload(kind) {
    return MAX_PAYLOAD[kind] ?? 0;
  }
  function readLength(buf, at, end = buf.length) {
    let value = 0;
    for (let i2 = 0; i2 < 4; i2++) {
      if (at + i2 >= end) return "short";
      const b = buf[at + i2];
      value += (b & 127) * 2 ** (7 * i2);
      if ((b & 128) === 0) return { value, used: i2 + 1 };
    }
    return "bad";
  }
  function readChunk(buf, start = 0, end = buf.length) {
    if (start >= end) return "short";
    const tag = buf[start];
    const kind = tag >> 5;
    const limit = maxPayload(kind);
    if (limit === 0) return "bad";
    const packet = kind === KIND_INTRA || kind === KIND_INTER;
    if (!packet && (tag & 31) !== 0) return "bad";
    if (end - start < 3) return "short";
    const seq = buf[start + 1] | buf[start + 2] << 8;
    const length = readLength(buf, start + 3, end);
    if (length === "short" || length === "bad") return length;
    if (length.value > limit) return "bad";
    const from = start + 3 + length.used;
    const to = from + length.value;
    if (end < to + 4) return "short";
    const crc = (buf[to] | buf[to + 1] << 8 | buf[to + 2] << 16 | buf[to + 3] << 24) >>> 0;
    if (crc32(buf, start, to) !== crc) return "bad";
    return {
      chunk: { kind, frames: packet ? (tag & 31) + 1 : 0, seq, payload: buf.slice(from, to) },
      used: to + 4 - start
    };
  }
  var ByteQueue = class {
    constructor() {
      this.buf = new Uint8Array(256);
      this.start = 0;
      this.end = 0;
    }
    /** Bytes held. */
    get length() {
      return this.end - this.start;
    }
    /** The backing array and the held bytes' bounds in it (valid until the next append). */
    view() {
      return { buf: this.buf, start: this.start, end: this.end };
    }
    append(bytes) {
      if (this.end + bytes.length > this.buf.length) {
        const held = this.end - this.start;
        if (held + bytes.length <= this.buf.length) {
          this.buf.copyWithin(0, this.start, this.end);
        } else {
          let size = this.buf.length;
          while (size < held + bytes.length) size *= 2;
          const next = new Uint8Array(size);
          next.set(this.buf.subarray(this.start, this.end));
          this.buf = next;
        }
        this.start = 0;
        this.end = held;
      }
      this.buf.set(bytes, this.end);
      this.end += bytes.length;
    }
    /** Drops the first `n` held bytes. */
    consume(n) {
      this.start += n;
      if (this.start === this.end) this.start = this.end = 0;
    }
  };

  // src/stream/header.ts
  var POSE_PARAMETERS = POSE_FIELDS.length;
  var MAX_VALUE = 2 ** 30;
  var MAX_SIDE = 16384;
  var InvalidHeader = class extends Error {
  };
  var Bytes = class {
    constructor(buf) {
      this.buf = buf;
      this.at = 0;
      this.view = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
    }
    take(n) {
      const at = this.skip(n);
      return this.buf.slice(at, at + n);
    }
    skip(n) {
      if (this.at + n > this.buf.length) throw new InvalidHeader("the stream header is cut short");
      const at = this.at;
      this.at += n;
      return at;
    }
    u8() {
      return this.buf[this.skip(1)];
    }
    u16() {
      return this.view.getUint16(this.skip(2), true);
    }
    u32() {
      return this.view.getUint32(this.skip(4), true);
    }
    i32() {
      return this.view.getInt32(this.skip(4), true);
    }
    f32() {
      return this.view.getFloat32(this.skip(4), true);
    }
  };
  function checkExtras(n, kinds) {
    const room = Math.max(n - POSE_PARAMETERS, 0);
    if (kinds.length > room) {
      throw new InvalidHeader(
        `${kinds.length} extra parameters do not fit in ${n} parameters per frame (at most ${room} after the pose)`
      );
    }
    for (let i2 = 0; i2 < kinds.length; i2++) {
      if (kinds[i2] === 0) throw new InvalidHeader(`extra parameter ${i2} has kind 0; kinds are 1-255`);
      for (let j = 0; j < i2; j++) {
        if (kinds[j] === kinds[i2]) throw new InvalidHeader(`extra parameter kind ${kinds[i2]} appears twice`);
      }
    }
  }
  function parseHeader(buf) {
    const b = new Bytes(buf);
    const magic = b.take(4);
    if (String.fromCharCode(...magic) !== "FMST") throw new InvalidHeader("not a facemime stream (no FMST header)");
    const version = b.u8();
    if (version !== 1 && version !== 2) {
      throw new InvalidHeader(`stream format version ${version}; this decoder reads versions 1 and 2`);
    }
    const fpsNum = b.u32();
    const fpsDen = b.u32();
    const width = b.u16();
    const height = b.u16();
    const topology = b.take(8);
    const packetFrames = b.u8();
    const keyframePackets = b.u16();
    const n = b.u8();
    if (n < POSE_PARAMETERS) {
      throw new InvalidHeader(`${n} parameters per frame is not within ${POSE_PARAMETERS}..255`);
    }
    const steps = [];
    const references = [];
    const classes = [];
    for (let i2 = 0; i2 < n; i2++) {
      steps.push(b.f32());
      references.push(b.i32());
      classes.push(b.u8());
    }
    let extras = [];
    if (version === 2) {
      const x2 = b.u8();
      extras = Array.from(b.take(x2));
      checkExtras(n, extras);
    }
    const basisLength = b.u16();
    const entries = (n - POSE_PARAMETERS - extras.length) * basisLength;
    const raw = b.take(2 * entries);
    const basis = new Int16Array(entries);
    for (let i2 = 0; i2 < entries; i2++) basis[i2] = (raw[2 * i2] | raw[2 * i2 + 1] << 8) << 16 >> 16;
    const actorId = b.take(32);
    const flag = b.u8();
    if (flag > 1) throw new InvalidHeader(`the header's actor flag is ${flag}, not 0 or 1`);
    if (b.at !== buf.length) throw new InvalidHeader(`the stream header has ${buf.length - b.at} bytes too many`);
    if (fpsNum === 0 || fpsDen === 0 || fpsNum / fpsDen > 1e3) {
      throw new InvalidHeader(`frame rate ${fpsNum}/${fpsDen} is not in (0, 1000] frames/s`);
    }
    if (width === 0 || height === 0 || width > MAX_SIDE || height > MAX_SIDE) {
      throw new InvalidHeader(`picture size ${width}x${height} is not within 1..${MAX_SIDE}`);
    }
    if (packetFrames === 0 || packetFrames > 32) {
      throw new InvalidHeader(`${packetFrames} frames per packet is not within 1..32`);
    }
    if (keyframePackets === 0) throw new InvalidHeader("the keyframe interval must be at least one packet");
    for (let i2 = 0; i2 < n; i2++) {
      if (!(Number.isFinite(steps[i2]) && steps[i2] > 0) || classes[i2] >= 16 || Math.abs(references[i2]) > MAX_VALUE) {
        throw new InvalidHeader(`parameter ${i2} has a bad quantiser (step ${steps[i2]}, class ${classes[i2]})`);
      }
    }
    return {
      version,
      fps: [fpsNum, fpsDen],
      width,
      height,
      topology,
      packetFrames,
      keyframePackets,
      steps,
      references,
      classes,
      extras,
      basisLength,
      basis,
      actorId,
      actorInStream: flag === 1
    };
  }
  function sameArray(a, b) {
    if (a.length !== b.length) return false;
    for (let i2 = 0; i2 < a.length; i2++) if (a[i2] !== b[i2]) return false;
    return true;
  }
  function sameHeader(a, b) {
    return a.fps[0] === b.fps[0] && a.fps[1] === b.fps[1] && a.width === b.width && a.height === b.height && sameArray(a.topology, b.topology) && a.packetFrames === b.packetFrames && a.keyframePackets === b.keyframePackets && sameArray(a.steps, b.steps) && sameArray(a.references, b.references) && sameArray(a.classes, b.classes) && sameArray(a.extras, b.extras) && a.basisLength === b.basisLength && sameArray(a.basis, b.basis) && sameArray(a.actorId, b.actorId) && a.actorInStream === b.actorInStream;
  }
  function dequantise(header, q) {
    const out = new Float64Array(q.length);
    for (let i2 = 0; i2 < q.length; i2++) out[i2] = q[i2] * header.steps[i2];
    return out;
  }

  // src/stream/range.ts
  var PRECISION = 12;
  var ONE = 1 << PRECISION;
  var RADIUS = 12;
  var ALPHABET = 2 * RADIUS + 2;
  var ESCAPE = ALPHABET - 1;
  var CLASSES = 16;
  var DECAY = [
    3764,
    6909,
    11147,
    16245,
    21852,
    27600,
    33170,
    38337,
    42966,
    47001,
    50443,
    53330,
    55718,
    57674,
    59263,
    60544
  ];
  var FLAG_SYMBOLS = 32;
  var LIMIT = 1 << 24;
  var InvalidPayload = class extends Error {
  };
  function tableFromFrequencies(freq) {
    const n = freq.length;
    let total = 0;
    for (let s = 0; s < n; s++) total += freq[s];
    const spare = ONE - n;
    const probs = new Array(n);
    let used = 0;
    let top = 0;
    for (let s = 0; s < n; s++) {
      probs[s] = 1 + Math.floor(freq[s] * spare / total);
      used += probs[s];
      if (freq[s] > freq[top]) top = s;
    }
    probs[top] += ONE - used;
    const cdf = new Uint16Array(n + 1);
    let acc = 0;
    for (let s = 0; s < n; s++) {
      acc += probs[s];
      cdf[s + 1] = acc;
    }
    return cdf;
  }
  function uniformTable(bits2) {
    const share = 1 << PRECISION - bits2;
    const cdf = new Uint16Array((1 << bits2) + 1);
    for (let s = 0; s <= 1 << bits2; s++) cdf[s] = s * share;
    return cdf;
  }
  var UNIFORM = Array.from({ length: PRECISION + 1 }, (_, b) => uniformTable(b));
  function startingFrequencies(c) {
    const f = new Array(ALPHABET).fill(0);
    let level = 4096;
    f[RADIUS] = level;
    for (let k = 1; k <= RADIUS; k++) {
      level = Math.max(1, Math.floor(level * DECAY[c] / 65536));
      f[RADIUS + k] = level;
      f[RADIUS - k] = level;
    }
    f[ESCAPE] = Math.max(1, level);
    return f;
  }
  var INTRA_TABLE = tableFromFrequencies(startingFrequencies(CLASSES - 1));
  var Context = class _Context {
    constructor(freq) {
      this.freq = Array.from(freq);
      this.total = this.freq.reduce((a, b) => a + b, 0);
      this.step = Math.max(1, this.total >> 4);
      this.table = tableFromFrequencies(this.freq);
    }
    /** The value context of spread class `c`. */
    static values(c) {
      return new _Context(startingFrequencies(c));
    }
    /** The frame-flags context: 16 for every symbol, 496 for symbol 1 (a face, nothing lost). */
    static flags() {
      const f = new Array(FLAG_SYMBOLS).fill(16);
      f[1] = 16 * (FLAG_SYMBOLS - 1);
      return new _Context(f);
    }
    /** Learns that `symbol` was decoded. */
    update(symbol) {
      this.freq[symbol] += this.step;
      this.total += this.step;
      if (this.total > LIMIT) {
        this.total = 0;
        for (let s = 0; s < this.freq.length; s++) {
          this.freq[s] = this.freq[s] + 1 >> 1;
          this.total += this.freq[s];
        }
      }
      this.table = tableFromFrequencies(this.freq);
    }
  };
  var RangeDecoder = class {
    /** Throws InvalidPayload for an odd payload length. */
    constructor(payload) {
      this.lower = 0;
      this.range = 4294967295;
      if (payload.length % 2 !== 0) throw new InvalidPayload("a packet's payload has an odd length");
      const n = payload.length / 2;
      this.words = new Uint16Array(n);
      for (let i2 = 0; i2 < n; i2++) this.words[i2] = payload[2 * i2] | payload[2 * i2 + 1] << 8;
      this.point = n >= 2 ? (this.words[0] << 16 | this.words[1]) >>> 0 : n === 1 ? this.words[0] << 16 >>> 0 : 0;
      this.next = Math.min(n, 2);
    }
    /** Decodes one symbol with `cdf`; throws InvalidPayload when the quantile is >= 4096. */
    symbol(cdf) {
      const scale2 = this.range >>> PRECISION;
      const quantile = Math.floor((this.point - this.lower >>> 0) / scale2);
      if (quantile >= ONE) throw new InvalidPayload("range decoder: invalid data");
      let lo = 0;
      let hi = cdf.length - 2;
      while (lo < hi) {
        const mid = lo + hi + 1 >> 1;
        if (cdf[mid] <= quantile) lo = mid;
        else hi = mid - 1;
      }
      const s = lo;
      this.lower = this.lower + scale2 * cdf[s] >>> 0;
      this.range = scale2 * (cdf[s + 1] - cdf[s]);
      if (this.range < 65536) {
        this.lower = this.lower << 16 >>> 0;
        this.range = this.range << 16 >>> 0;
        const w = this.next < this.words.length ? this.words[this.next] : 0;
        this.next++;
        this.point = (this.point << 16 | w) >>> 0;
      }
      return s;
    }
    /** Decodes an integer with value table `cdf`: the value and the table's symbol (the escape's
     * extra symbols are uniform: sign, bit length n of m = |v| - 13, then m's n - 1 low bits in
     * chunks of at most 12, most significant first). */
    value(cdf) {
      const symbol = this.symbol(cdf);
      if (symbol !== ESCAPE) return { value: symbol - RADIUS, symbol };
      const negative = this.symbol(UNIFORM[1]) === 1;
      const n = this.symbol(UNIFORM[5]);
      let m = n === 0 ? 0 : 1;
      let left = Math.max(n - 1, 0);
      while (left > 0) {
        const b = Math.min(left, PRECISION);
        m = m * 2 ** b + this.symbol(UNIFORM[b]);
        left -= b;
      }
      const magnitude = m + RADIUS + 1;
      return { value: negative ? -magnitude : magnitude, symbol };
    }
  };

  // src/stream/packet.ts
  var FACE = 1;
  var CodingState = class {
    /** The state at the start of an intra packet. */
    constructor(header) {
      this.flags = Context.flags();
      /** The last frame with a face since the intra packet: what the next one is predicted from. */
      this.pred = null;
      this.values = header.classes.map((c) => Context.values(c));
      this.references = header.references;
    }
  };
  function decodePacket(state, payload, frames) {
    const dec = new RangeDecoder(payload);
    const n = state.references.length;
    const out = [];
    for (let j = 0; j < frames; j++) {
      const flags = dec.symbol(state.flags.table);
      state.flags.update(flags);
      if ((flags & FACE) === 0) {
        out.push({ flags, q: null });
        continue;
      }
      const q = new Int32Array(n);
      const pred = state.pred;
      for (let i2 = 0; i2 < n; i2++) {
        let v2;
        if (pred) {
          const r = dec.value(state.values[i2].table);
          state.values[i2].update(r.symbol);
          v2 = pred[i2] + r.value;
        } else {
          v2 = state.references[i2] + dec.value(INTRA_TABLE).value;
        }
        if (Math.abs(v2) > MAX_VALUE) throw new InvalidPayload(`parameter ${i2} decodes to ${v2}, beyond the format's range`);
        q[i2] = v2;
      }
      state.pred = q;
      out.push({ flags, q });
    }
    return out;
  }

  // src/stream/decoder.ts
  var MAX_GAP_PACKETS = 256;
  var StreamDecoder = class {
    /** `fromStart`: the bytes start at the stream's start (a file: missing leading packets are
     * concealed); false for a receiver joining a live stream at the first packet it gets. */
    constructor(fromStart = true) {
      this.fromStart = fromStart;
      /** What the decoder met so far. */
      this.stats = {
        packets: 0,
        lost_packets: 0,
        late_packets: 0,
        undecodable: 0,
        appearance: 0,
        damaged_runs: 0,
        damaged_bytes: 0,
        frames: 0,
        concealed: 0
      };
      this.queue = new ByteQueue();
      this.inDamage = false;
      this.current = null;
      this.refused = null;
      this.actorData = null;
      this.state = null;
      /** The next expected packet number (unwrapped), once a packet was read. */
      this.next = null;
      /** The quantised parameters of the last face (the header's references before any). */
      this.shown = new Int32Array(0);
      /** The last good decoded frame, which concealed frames repeat. */
      this.last = null;
      this.raw = [];
      /** The header the output's current part was read under. */
      this.partHeader = null;
    }
    /** The header in force, once one was read. */
    get header() {
      return this.current;
    }
    /** Why the last well-framed header was refused, if one was. */
    get headerError() {
      return this.refused;
    }
    /** The last actor chunk's payload, once one was read. */
    get actor() {
      return this.actorData;
    }
    /** Reads `bytes` (after what is buffered); returns the events they completed. */
    push(bytes) {
      this.queue.append(bytes);
      this.drain(false);
      return this.output();
    }
    /** Reads what is buffered as the stream's end (a chunk cut short there is damage). */
    finish() {
      this.drain(true);
      return this.output();
    }
    drain(end) {
      const { buf, start, end: stop } = this.queue.view();
      let at = start;
      while (at < stop) {
        const r = readChunk(buf, at, stop);
        if (r === "short" && !end) break;
        if (r === "short" || r === "bad") {
          if (!this.inDamage) {
            this.stats.damaged_runs++;
            this.inDamage = true;
          }
          this.stats.damaged_bytes++;
          at++;
          continue;
        }
        this.inDamage = false;
        at += r.used;
        this.chunk(r.chunk);
      }
      this.queue.consume(at - start);
    }
    chunk(c) {
      switch (c.kind) {
        case KIND_HEADER: {
          let h;
          try {
            h = parseHeader(c.payload);
          } catch (e) {
            if (!(e instanceof InvalidHeader)) throw e;
            this.refused = e.message;
            return;
          }
          if (this.current && sameHeader(this.current, h)) return;
          this.shown = Int32Array.from(h.references);
          this.current = h;
          this.state = null;
          this.next = null;
          this.raw.push({ t: "event", event: { kind: "header", header: h } });
          return;
        }
        case KIND_ACTOR:
          this.actorData = c.payload;
          this.raw.push({ t: "event", event: { kind: "actor", data: c.payload } });
          return;
        case KIND_APPEARANCE:
          if (!this.current || c.payload.length < APPEARANCE_PREFIX) {
            this.stats.undecodable++;
            return;
          }
          this.stats.appearance++;
          this.raw.push({ t: "event", event: { kind: "appearance", payload: c.payload } });
          return;
        default:
          this.packet(c);
      }
    }
    packet(c) {
      const header = this.current;
      if (!header) {
        this.stats.undecodable++;
        return;
      }
      const per = header.packetFrames;
      const expected = this.next ?? (this.fromStart ? 0 : c.seq);
      const delta = (c.seq - expected % 65536 + 65536) % 65536;
      if (delta >= 1 << 15) {
        this.stats.late_packets++;
        return;
      }
      const seq = expected + delta;
      if (delta > 0) {
        this.stats.lost_packets += delta;
        this.state = null;
        if (delta <= MAX_GAP_PACKETS) this.conceal(expected * per, delta * per);
      }
      this.next = seq + 1;
      const first = seq * per;
      if (c.frames > per) {
        this.stats.undecodable++;
        this.state = null;
        this.conceal(first, c.frames);
        return;
      }
      if (c.kind === KIND_INTRA) this.state = new CodingState(header);
      if (!this.state) {
        this.conceal(first, c.frames);
        return;
      }
      let frames;
      try {
        frames = decodePacket(this.state, c.payload, c.frames);
      } catch (e) {
        if (!(e instanceof InvalidPayload)) throw e;
        this.stats.undecodable++;
        this.state = null;
        this.conceal(first, c.frames);
        return;
      }
      this.stats.packets++;
      this.stats.frames += frames.length;
      frames.forEach((f, j) => {
        const face = (f.flags & FACE) !== 0;
        if (f.q) this.shown = f.q;
        const frame = {
          index: first + j,
          face,
          lost: f.flags >> 1 & 15,
          q: this.shown.slice(),
          values: dequantise(header, this.shown),
          concealed: false
        };
        this.raw.push({ t: "frame", frame });
      });
    }
    conceal(first, count) {
      if (count > 0) {
        this.stats.concealed += count;
        this.raw.push({ t: "concealed", first, count });
      }
    }
    /** This call's events, in parts split where a header starts a new stream (the header event
     * between them), as MotionDecoder reads them (the Rust decoder's segments): in each part its
     * frames in index order (a stable sort, decoded frames before concealed runs on a tie),
     * concealed runs filled in, each other event after as many frames as the decoder had output
     * before reading it. */
    output() {
      const raw = this.raw;
      this.raw = [];
      const out = [];
      let part = [];
      for (const r of raw) {
        if (r.t === "event" && r.event.kind === "header") {
          out.push(...this.part(part), r.event);
          this.partHeader = r.event.header;
          part = [];
        } else {
          part.push(r);
        }
      }
      out.push(...this.part(part));
      return out;
    }
    /** One part of a call's output, read under the header `partHeader`. */
    part(raw) {
      const runs = [];
      const others = [];
      let seen = 0;
      for (const r of raw) {
        if (r.t === "frame") {
          runs.push({ first: r.frame.index, frame: r.frame, count: 1 });
          seen++;
        } else if (r.t === "concealed") {
          seen += r.count;
        } else {
          others.push({ before: seen, event: r.event });
        }
      }
      for (const r of raw) if (r.t === "concealed") runs.push({ first: r.first, frame: null, count: r.count });
      runs.sort((a, b) => a.first - b.first);
      const out = [];
      let k = 0;
      let emitted = 0;
      const flush = () => {
        while (k < others.length && others[k].before <= emitted) out.push(others[k++].event);
      };
      flush();
      for (const run of runs) {
        if (run.frame) {
          this.last = run.frame;
          out.push({ kind: "frame", frame: run.frame });
          emitted++;
          flush();
          continue;
        }
        for (let j = 0; j < run.count; j++) {
          out.push({ kind: "frame", frame: this.concealedFrame(run.first + j) });
          emitted++;
          flush();
        }
      }
      while (k < others.length) out.push(others[k++].event);
      return out;
    }
    concealedFrame(index) {
      const last = this.last;
      if (last) {
        return { index, face: last.face, lost: last.lost, q: last.q.slice(), values: last.values.slice(), concealed: true };
      }
      const header = this.partHeader;
      const q = new Int32Array(header.references.length);
      for (let i2 = 0; i2 < POSE_PARAMETERS; i2++) q[i2] = header.references[i2];
      return { index, face: false, lost: 15, q, values: dequantise(header, q), concealed: true };
    }
  };

  // src/main.ts
  var WINDOW_S = 5;
  var INTRA_EVERY_MS = 250;
  var canvas = document.getElementById("picture");
  var hud = document.getElementById("hud");
  var message = document.getElementById("message");
  var params = new URLSearchParams(location.search);
  var dropShare = Number(params.get("drop") ?? 0);
  var slowMs = Number(params.get("slow") ?? 0);
  var seed = Number(params.get("seed") ?? 1) >>> 0 || 1;
  var random = () => {
    seed ^= seed << 13;
    seed >>>= 0;
    seed ^= seed >>> 17;
    seed ^= seed << 5;
    seed >>>= 0;
    return seed / 2 ** 32;
  };
  var renderer = new Renderer(canvas);
  var now = () => performance.timeOrigin + performance.now();
  var Session = class {
    constructor(live) {
      this.header = null;
      this.actor = null;
      this.texture = null;
      this.synth = null;
      this.frames = [];
      /** Appearance updates with the number of frames output before each was read. */
      this.updates = [];
      this.applied = 0;
      this.pending = Promise.resolve();
      this.decoder = new StreamDecoder(!live);
    }
    /** Takes the decoder's events in order (actor and images decode asynchronously, in turn). */
    take(events, onFrame) {
      for (const e of events) {
        this.pending = this.pending.then(async () => {
          if (e.kind === "header") {
            if (this.header && this.actor && !same(this.header.actorId, e.header.actorId)) this.actor = null;
            this.header = e.header;
            this.synth = null;
            this.updates = [];
            this.applied = 0;
            this.frames = [];
            this.build();
          } else if (e.kind === "actor") {
            if (!this.actor) {
              const t0 = performance.now();
              this.actor = await readActor(e.data);
              this.build();
              counts.setupMs = performance.now() - t0;
            }
          } else if (e.kind === "appearance") {
            const update = await readUpdate(e.payload);
            if (update) this.updates.push({ update, after: this.frames.length });
            else api.counts.refused += 1;
          } else {
            await nextTask();
            this.frames.push(e.frame);
            onFrame(e.frame);
          }
        });
      }
      return this.pending;
    }
    build() {
      if (!this.header || !this.actor || this.synth) return;
      this.texture = { ...this.actor.texture, rgba: this.actor.texture.rgba.slice() };
      this.applied = 0;
      this.synth = new Synthesizer(renderer, this.actor, this.header);
      const [w, h] = [this.header.width, this.header.height];
      if (canvas.width !== w || canvas.height !== h) {
        canvas.width = w;
        canvas.height = h;
      }
    }
    /** Draws ``frame`` (its updates applied first); false when the actor is not here yet. */
    draw(frame, position) {
      if (!this.synth || !this.texture || !this.header) return false;
      let changed = false;
      while (this.applied < this.updates.length) {
        const { update, after } = this.updates[this.applied];
        if (after > position || update.frame > frame.index) break;
        if (applyUpdate(this.texture, update)) changed = true;
        else api.counts.refused += 1;
        this.applied += 1;
      }
      if (changed) this.synth.retexture(this.texture);
      const [w, h] = this.synth.size;
      this.synth.draw(frame, letterbox(w, h, canvas.width, canvas.height));
      return true;
    }
  };
  function nextTask() {
    return new Promise((resolve) => {
      const channel = new MessageChannel();
      channel.port1.onmessage = () => resolve();
      channel.port2.postMessage(null);
    });
  }
  function same(a, b) {
    return a.length === b.length && a.every((x2, i2) => x2 === b[i2]);
  }
  function letterbox(w, h, cw, ch) {
    const f = Math.min(cw / w, ch / h);
    const sw = Math.max(1, Math.round(w * f)), sh = Math.max(1, Math.round(h * f));
    return [Math.floor((cw - sw) / 2), Math.floor((ch - sh) / 2), sw, sh];
  }
  var counts = { drawn: 0, intraRequests: 0, dropped: 0, refused: 0, received: 0, setupMs: 0 };
  var latencies = [];
  var drawTimes = [];
  var drawnAt = [];
  var bytesAt = [];
  var arrived = /* @__PURE__ */ new Map();
  var session = null;
  var lastRequest = -Infinity;
  var outOfSync = false;
  var retry = null;
  var socket = null;
  function present(frame, position) {
    if (!session) return;
    const t0 = performance.now();
    if (!session.draw(frame, position)) return;
    renderer.gl.finish();
    while (performance.now() - t0 < slowMs) ;
    const t1 = performance.now();
    drawTimes.push(t1 - t0);
    counts.drawn += 1;
    drawnAt.push(t1);
    const sent = arrived.get(frame.index);
    if (sent !== void 0 && !frame.concealed) latencies.push([frame.index, now() - sent]);
    arrived.delete(frame.index);
  }
  function updateHud() {
    const t = performance.now();
    while (drawnAt.length && drawnAt[0] < t - WINDOW_S * 1e3) drawnAt.shift();
    while (bytesAt.length && bytesAt[0][0] < t - WINDOW_S * 1e3) bytesAt.shift();
    const fps = drawnAt.length / WINDOW_S;
    const kbps = bytesAt.reduce((s2, [, b]) => s2 + b, 0) * 8 / 1e3 / WINDOW_S;
    const s = session?.decoder.stats;
    const lat = latencies.length ? `, latency ${median2(latencies.slice(-50).map((l) => l[1])).toFixed(0)} ms` : "";
    hud.textContent = `${fps.toFixed(1)} frames/s drawn · ${kbps.toFixed(2)} kbit/s received · ${s?.concealed ?? 0} frames concealed (${s?.lost_packets ?? 0} packets lost)${lat}`;
  }
  function median2(xs) {
    const s = [...xs].sort((a, b) => a - b);
    return s.length ? s[Math.floor(s.length / 2)] : NaN;
  }
  function fail(text) {
    api.error = text;
    message.textContent = text;
    message.hidden = false;
  }
  function requestIntra() {
    if (!socket || socket.readyState !== WebSocket.OPEN || retry !== null) return;
    const wait = lastRequest + INTRA_EVERY_MS - performance.now();
    if (wait <= 0) {
      lastRequest = performance.now();
      counts.intraRequests += 1;
      socket.send(JSON.stringify({ type: "intra" }));
    }
    retry = setTimeout(() => {
      retry = null;
      if (outOfSync) requestIntra();
    }, wait > 0 ? wait : INTRA_EVERY_MS);
  }
  function connect() {
    const live = new Session(true);
    session = live;
    outOfSync = false;
    const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/stream`);
    ws.binaryType = "arraybuffer";
    socket = ws;
    ws.onopen = () => {
      message.hidden = true;
      requestIntra();
    };
    ws.onmessage = (m) => {
      if (typeof m.data === "string") {
        const note = JSON.parse(m.data);
        if (note.type === "frames") note.arrived.forEach((t, j) => arrived.set(note.first + j, t));
        if (note.type === "end") message.textContent = "the call has ended";
        if (note.type === "end") message.hidden = false;
        return;
      }
      const bytes = new Uint8Array(m.data);
      const kind = bytes[0] >> 5;
      if (kind === KIND_INTRA || kind === KIND_INTER) {
        if (dropShare > 0 && random() < dropShare) {
          counts.dropped += 1;
          return;
        }
        counts.received += bytes.length;
        bytesAt.push([performance.now(), bytes.length]);
      }
      const events = live.decoder.push(bytes);
      for (const e of events) if (e.kind === "frame") outOfSync = e.frame.concealed;
      if (outOfSync) requestIntra();
      live.take(events, (f) => {
        api.frames.push(shown(f));
        present(f, live.frames.length - 1);
      }).catch((e) => fail(`cannot play the call: ${e.message}`));
    };
    ws.onclose = (e) => {
      socket = null;
      if (session === live && e.code !== 1e3) {
        message.textContent = "the sender is gone: reconnecting…";
        message.hidden = false;
        setTimeout(connect, 1e3);
      }
    };
  }
  function shown(f) {
    return { index: f.index, face: f.face, concealed: f.concealed, lost: f.lost, values: Array.from(f.values) };
  }
  var playing = 0;
  async function loadStream(data, autoplay = true) {
    const bytes = typeof data === "string" ? Uint8Array.from(atob(data), (c) => c.charCodeAt(0)) : data;
    socket?.close(1e3);
    const file = new Session(false);
    session = file;
    api.frames = [];
    const collect = (f) => {
      api.frames.push(shown(f));
    };
    await file.take(file.decoder.push(bytes), collect);
    await file.take(file.decoder.finish(), collect);
    if (!file.header) throw new Error("this is not a facemime stream (no header found)");
    if (!file.synth) throw new Error("the stream does not carry its actor");
    message.hidden = true;
    const run = ++playing;
    if (!autoplay) return;
    const fps = file.header.fps[0] / file.header.fps[1];
    const start = performance.now();
    const tick = () => {
      if (run !== playing || session !== file) return;
      const i2 = Math.floor((performance.now() - start) / 1e3 * fps) % file.frames.length;
      present(file.frames[i2], i2);
      updateHud();
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }
  var api = {
    frames: [],
    counts,
    error: null,
    stats: () => ({
      ...session?.decoder.stats ?? {},
      ...counts,
      latencies: [...latencies],
      drawTimes: [...drawTimes],
      header: session?.header ? { width: session.header.width, height: session.header.height, fps: session.header.fps } : null
    }),
    loadStream: (data, autoplay = true) => loadStream(data, autoplay),
    show: (index) => {
      if (!session) throw new Error("no stream loaded");
      playing += 1;
      const position = session.frames.findIndex((f) => f.index === index);
      if (position < 0) throw new Error(`no frame ${index}`);
      session.texture = session.actor ? { ...session.actor.texture, rgba: session.actor.texture.rgba.slice() } : null;
      session.applied = 0;
      if (session.texture) session.synth?.retexture(session.texture);
      present(session.frames[position], position);
    },
    pixels: () => {
      const p = renderer.pixels();
      let s = "";
      for (let i2 = 0; i2 < p.length; i2 += 32768) s += String.fromCharCode(...p.subarray(i2, i2 + 32768));
      return btoa(s);
    },
    benchmark: (count) => {
      if (!session?.synth) throw new Error("no stream loaded");
      playing += 1;
      const t0 = performance.now();
      for (let i2 = 0; i2 < count; i2++) {
        const f = session.frames[i2 % session.frames.length];
        session.synth.draw(f, [0, 0, canvas.width, canvas.height]);
        renderer.gl.finish();
      }
      return (performance.now() - t0) / count;
    }
  };
  window.facemime = api;
  var chooser = document.getElementById("file");
  var play = (f) => f.arrayBuffer().then((b) => loadStream(new Uint8Array(b))).catch((e) => fail(`cannot play ${f.name}: ${e.message}`));
  chooser.onchange = () => {
    if (chooser.files?.[0]) void play(chooser.files[0]);
  };
  document.body.ondragover = (e) => e.preventDefault();
  document.body.ondrop = (e) => {
    e.preventDefault();
    const f = e.dataTransfer?.files[0];
    if (f) void play(f);
  };
  setInterval(updateHud, 500);
  if (location.protocol.startsWith("http") && params.get("live") !== "0") connect();
  else {
    message.textContent = "drop a .fmstream file here, or choose one";
    message.hidden = false;
  }
})();
