// Progressive loading of a splitstream file over HTTP range requests, with
// no DOM: the part of the viewer a page, a worker or node can share.
//
//   const mesh = await ProgressiveMesh.open(url, StreamDecoder);
//   for await (const step of mesh.refine(mesh.levelFor(view))) draw(mesh.decoder);
//
// `StreamDecoder` is passed in, so the same code runs on the `--target web`
// build (browsers) and the `--target nodejs` build (the tests).
//
// Requests: the first 96 bytes, the head (header and level table), then
// each level's byte range once, in order, only as far as the view needs.
// A server that ignores `Range` (status 200) costs one full download,
// which is then sliced.

/** Bytes the header occupies before the level table (SPEC §3). */
const HEADER_BYTES = 96;

/** Fetches bytes [start, end) of `url` with a `Range` request. */
export async function fetchRange(url, start, end, { fetch: fetchFn = fetch } = {}) {
  const response = await fetchFn(url, { headers: { Range: `bytes=${start}-${end - 1}` } });
  if (!response.ok) {
    throw new Error(`${url}: HTTP ${response.status} for bytes ${start}-${end - 1}`);
  }
  const body = new Uint8Array(await response.arrayBuffer());
  if (response.status === 206) {
    if (body.length !== end - start) {
      throw new Error(`${url}: asked for ${end - start} bytes at ${start}, got ${body.length}`);
    }
    return { bytes: body, whole: null };
  }
  // 200: the server sent the whole file.
  if (body.length < end) {
    throw new Error(`${url}: the file has ${body.length} bytes, the stream needs ${end}`);
  }
  return { bytes: body.subarray(start, end), whole: body };
}

export class ProgressiveMesh {
  /**
   * Fetches the head of the stream at `url` and makes its decoder.
   * `options.maxBytes` caps the decoder's memory (it then decodes the
   * levels that fit, `StreamDecoder.withinBudget`); `options.fetch`
   * replaces the global `fetch`.
   */
  static async open(url, StreamDecoder, options = {}) {
    const mesh = new ProgressiveMesh(url, options);
    const first = await mesh.#range(0, HEADER_BYTES);
    const head = await mesh.#range(0, StreamDecoder.headLength(first));
    mesh.decoder =
      options.maxBytes === undefined
        ? new StreamDecoder(head)
        : StreamDecoder.withinBudget(head, options.maxBytes);
    return mesh;
  }

  constructor(url, options) {
    this.url = url;
    this.options = options;
    /** Bytes received over the network, for the page's status line. */
    this.bytesFetched = 0;
    /** The whole file, when a server answered a range with all of it. */
    this.whole = null;
    this.decoder = null;
  }

  /** Levels the decoder can hold (all unless `maxBytes` was given). */
  get levelCount() {
    return this.decoder.levelsThatFit;
  }

  /**
   * The coarsest level whose geometric error spans at most `maxPixels`
   * pixels at `distance` model units from a perspective camera with a
   * viewport `viewportHeight` pixels high and a vertical field of view of
   * `fovY` radians; clamped to the levels that fit.
   */
  levelFor({ viewportHeight, fovY, distance, maxPixels = 1 }) {
    const level = this.decoder.levelForScreenError(viewportHeight, fovY, distance, maxPixels);
    return Math.min(level, this.levelCount - 1);
  }

  /**
   * Decodes levels up to `target`, fetching each one's bytes when it is
   * reached. Yields `{ level, round }` after level 0's seed (round 0) and
   * after every round of every level (rounds count from 1), so the caller
   * can draw between rounds. Levels already decoded are not decoded again;
   * asking for a coarser level than decoded yields nothing.
   */
  async *refine(target) {
    const d = this.decoder;
    const last = Math.min(target, this.levelCount - 1);
    for (let k = d.nextLevel; k !== undefined && k <= last; k = d.nextLevel) {
      const [start, end] = d.levelRange(k);
      const bytes = await this.#range(start, end);
      d.beginLevel(k, bytes);
      if (k === 0) yield { level: 0, round: 0 }; // the seed (SPEC §6)
      for (let round = 1; d.nextRound(); round++) yield { level: k, round };
    }
  }

  /** Releases the decoder's wasm memory. */
  free() {
    this.decoder?.free();
    this.decoder = null;
  }

  async #range(start, end) {
    if (this.whole) return this.whole.subarray(start, end);
    const { bytes, whole } = await fetchRange(this.url, start, end, this.options);
    this.whole = whole;
    this.bytesFetched += whole ? whole.length : bytes.length;
    return bytes;
  }
}
