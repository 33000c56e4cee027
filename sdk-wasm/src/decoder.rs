//! `StreamDecoder`: the progressive decoder for JavaScript.

use splitstream_decoder_core::LevelInfo;
use splitstream_sdk_native::{ScreenView, Session};
use wasm_bindgen::prelude::*;

use crate::error::SdkError;

/// A progressive decoder. Create it from the stream head (header and level
/// table: `StreamDecoder.headLength(first96Bytes)` bytes, or the whole
/// stream), fetch each level's byte range (`levelRange(k)`), and decode it
/// whole (`decodeLevel`) or round by round (`beginLevel`, then `nextRound`
/// until it returns false), drawing the mesh in between.
///
/// Memory: the workspace the whole stream needs (`workspaceBytes`, from the
/// header) is allocated once, here; the first call of `positions()` or
/// `positionsF64()` adds one buffer for the dequantized positions of the
/// whole stream (12 or 24 bytes per vertex). Otherwise only the level
/// bytes passed in are copied (and kept by `beginLevel` until the level
/// completes).
#[wasm_bindgen]
pub struct StreamDecoder {
    session: Session,
    /// Dequantized positions, reserved for the whole stream on first use.
    out_f32: Vec<f32>,
    out_f64: Vec<f64>,
}

#[wasm_bindgen]
impl StreamDecoder {
    /// Bytes of header and level table, from the stream's first 96 bytes.
    #[wasm_bindgen(js_name = headLength)]
    pub fn head_length(header: &[u8]) -> Result<usize, SdkError> {
        Ok(Session::head_len(header)?)
    }

    /// Parses the header and level table at the start of `head` and
    /// allocates the workspace.
    #[wasm_bindgen(constructor)]
    pub fn new(head: &[u8]) -> Result<StreamDecoder, SdkError> {
        Ok(StreamDecoder {
            session: Session::open(head)?,
            out_f32: Vec::new(),
            out_f64: Vec::new(),
        })
    }

    /// As the constructor, with at most `maxBytes` of working memory: the
    /// decoder holds the longest prefix of levels that fits (`levelsThatFit`)
    /// and decodes those, a phone's memory budget. Throws
    /// `capacity-exceeded` when not even the base level fits.
    #[wasm_bindgen(js_name = withinBudget)]
    pub fn within_budget(head: &[u8], max_bytes: f64) -> Result<StreamDecoder, SdkError> {
        if max_bytes.is_nan() || max_bytes < 0.0 {
            return Err(SdkError::argument(format!(
                "budget {max_bytes} is not a number of bytes"
            )));
        }
        // Past 2^64 every budget is unlimited; `as` saturates.
        Ok(StreamDecoder {
            session: Session::open_within(head, max_bytes as u64)?,
            out_f32: Vec::new(),
            out_f64: Vec::new(),
        })
    }

    /// Levels the working memory holds: all of them unless made with
    /// `withinBudget`.
    #[wasm_bindgen(getter, js_name = levelsThatFit)]
    pub fn levels_that_fit(&self) -> u16 {
        self.session.levels_that_fit()
    }

    /// Levels in the stream, the base level 0 included.
    #[wasm_bindgen(getter, js_name = levelCount)]
    pub fn level_count(&self) -> u16 {
        self.session.level_count()
    }

    /// Levels completely decoded.
    #[wasm_bindgen(getter, js_name = levelsDone)]
    pub fn levels_done(&self) -> u16 {
        self.session.levels_done()
    }

    /// The level to fetch and decode next; undefined when all are done,
    /// while a level is decoded round by round, or after an error.
    #[wasm_bindgen(getter, js_name = nextLevel)]
    pub fn next_level(&self) -> Option<u16> {
        self.session.next_level()
    }

    /// Bytes of working memory held (decoder-core SPEC §9).
    #[wasm_bindgen(getter, js_name = workspaceBytes)]
    pub fn workspace_bytes(&self) -> f64 {
        self.session.workspace_bytes() as f64
    }

    /// Level `level`'s byte range `[start, end)` in the stream, for an HTTP
    /// range request (`bytes=start-(end-1)`).
    #[wasm_bindgen(js_name = levelRange)]
    pub fn level_range(&self, level: u16) -> Result<Vec<f64>, SdkError> {
        let e = self.info(level)?;
        Ok(vec![e.offset as f64, (e.offset + e.length as u64) as f64])
    }

    /// Vertices once level `level` is decoded.
    #[wasm_bindgen(js_name = levelVertexCount)]
    pub fn level_vertex_count(&self, level: u16) -> Result<u32, SdkError> {
        Ok(self.info(level)?.vertex_count)
    }

    /// Triangles once level `level` is decoded.
    #[wasm_bindgen(js_name = levelTriangleCount)]
    pub fn level_triangle_count(&self, level: u16) -> Result<u32, SdkError> {
        Ok(self.info(level)?.triangle_count)
    }

    /// Refinement rounds in level `level` (0 for the base level).
    #[wasm_bindgen(js_name = levelRoundCount)]
    pub fn level_round_count(&self, level: u16) -> Result<u32, SdkError> {
        Ok(self.info(level)?.round_count)
    }

    /// The encoder's estimate of level `level`'s distance to the original.
    #[wasm_bindgen(js_name = levelGeometricError)]
    pub fn level_geometric_error(&self, level: u16) -> Result<f32, SdkError> {
        Ok(self.info(level)?.geometric_error)
    }

    /// The coarsest level whose geometric error (model units) is at most
    /// `maxError`, the last level that fits when none is: decode levels 0
    /// to it. Throws `invalid-argument` for a NaN or negative `maxError`
    /// (as `levelForScreenError` does for its parameters).
    #[wasm_bindgen(js_name = levelWithinError)]
    pub fn level_within_error(&self, max_error: f32) -> Result<u16, SdkError> {
        self.session
            .checked_level_within_error(max_error)
            .map_err(|e| SdkError::argument(e.to_string()))
    }

    /// The coarsest level whose geometric error covers at most `maxPixels`
    /// pixels for a perspective camera `viewportHeight` pixels high with a
    /// vertical field of view of `fovY` radians, at `distance` model units
    /// from the object: how many levels to fetch and decode for this view.
    /// Throws `invalid-argument` for parameters that describe no camera.
    #[wasm_bindgen(js_name = levelForScreenError)]
    pub fn level_for_screen_error(
        &self,
        viewport_height: f32,
        fov_y: f32,
        distance: f32,
        max_pixels: f32,
    ) -> Result<u16, SdkError> {
        ScreenView::perspective(viewport_height, fov_y)
            .and_then(|view| {
                self.session
                    .level_for_screen_error(&view, distance, max_pixels)
            })
            .map_err(|e| SdkError::argument(e.to_string()))
    }

    /// Decodes level `level` whole from exactly its bytes.
    #[wasm_bindgen(js_name = decodeLevel)]
    pub fn decode_level(&mut self, level: u16, bytes: &[u8]) -> Result<(), SdkError> {
        Ok(self.session.decode_level(level, bytes)?)
    }

    /// Starts level `level` (its bytes are copied) for `nextRound`; level
    /// 0's seed mesh is decoded here.
    #[wasm_bindgen(js_name = beginLevel)]
    pub fn begin_level(&mut self, level: u16, bytes: &[u8]) -> Result<(), SdkError> {
        Ok(self.session.begin_level(level, bytes)?)
    }

    /// Decodes the next round of the begun level: true when a round was
    /// decoded, false when the level is complete (and checked) or none is
    /// begun.
    #[wasm_bindgen(js_name = nextRound)]
    pub fn next_round(&mut self) -> Result<bool, SdkError> {
        Ok(self.session.next_round()?.is_some())
    }

    #[wasm_bindgen(getter, js_name = vertexCount)]
    pub fn vertex_count(&self) -> u32 {
        self.session.positions().len() as u32
    }

    #[wasm_bindgen(getter, js_name = triangleCount)]
    pub fn triangle_count(&self) -> u32 {
        self.session.triangles().len() as u32
    }

    /// The state hash of the current mesh (decoder-core SPEC §8), a BigInt.
    #[wasm_bindgen(js_name = stateHash)]
    pub fn state_hash(&self) -> u64 {
        self.session.state_hash()
    }

    /// The state hash as 16 lowercase hex digits (as conformance manifests
    /// write it).
    #[wasm_bindgen(js_name = stateHashHex)]
    pub fn state_hash_hex(&self) -> String {
        format!("{:016x}", self.session.state_hash())
    }

    /// Quantized positions, x, y, z per vertex (a copy).
    #[wasm_bindgen(js_name = positionsQuantized)]
    pub fn positions_quantized(&self) -> js_sys::Uint32Array {
        self.session.positions().as_flattened().into()
    }

    /// Triangle corners, three vertex indices per triangle,
    /// counter-clockwise (a copy; an index buffer for drawing).
    pub fn indices(&self) -> js_sys::Uint32Array {
        self.session.triangles().as_flattened().into()
    }

    /// Real positions as 32-bit floats, x, y, z per vertex (a copy; a
    /// vertex buffer for drawing).
    pub fn positions(&mut self) -> js_sys::Float32Array {
        self.fill_f32().into()
    }

    /// Real positions as 64-bit floats, x, y, z per vertex (a copy).
    #[wasm_bindgen(js_name = positionsF64)]
    pub fn positions_f64(&mut self) -> js_sys::Float64Array {
        self.fill_f64().into()
    }
}

impl StreamDecoder {
    fn info(&self, level: u16) -> Result<LevelInfo, SdkError> {
        self.session.level_info(level).ok_or_else(|| {
            SdkError::argument(format!(
                "level {level} beyond the stream's {} levels",
                self.session.level_count()
            ))
        })
    }

    /// The whole stream's coordinates: what the scratch buffers reserve.
    fn capacity(&self) -> usize {
        3 * self.session.header().vertex_capacity as usize
    }

    /// Dequantizes into the `f32` scratch (reserved once for the stream).
    pub fn fill_f32(&mut self) -> &[f32] {
        if self.out_f32.capacity() == 0 {
            self.out_f32.reserve_exact(self.capacity());
        }
        self.out_f32.clear();
        for &q in self.session.positions() {
            self.out_f32
                .extend(self.session.dequantize(q).map(|c| c as f32));
        }
        &self.out_f32
    }

    /// Dequantizes into the `f64` scratch (reserved once for the stream).
    pub fn fill_f64(&mut self) -> &[f64] {
        if self.out_f64.capacity() == 0 {
            self.out_f64.reserve_exact(self.capacity());
        }
        self.out_f64.clear();
        for &q in self.session.positions() {
            self.out_f64.extend(self.session.dequantize(q));
        }
        &self.out_f64
    }

    /// The session wrapped (for Rust callers and tests).
    pub fn session(&self) -> &Session {
        &self.session
    }
}
