//! GeoTIFF elevation rasters via the `tiff` crate (uncompressed, PackBits,
//! LZW, DEFLATE and ZSTD, with their predictors; strips or tiles; the first
//! image of a cloud-optimized GeoTIFF, its full resolution).
//!
//! Only the first band is used (every other sample of chunky multi-band
//! images is skipped; planar images are read plane 0 only). Georeferencing
//! comes from ModelPixelScaleTag (33550) + ModelTiepointTag (33922), or a
//! non-rotated ModelTransformationTag (34264); without either the spacing is
//! 1 and the south-west sample sits at the origin. GDAL_NODATA (42113) marks
//! missing samples. Raster row 0 is north. With the default
//! PixelIsArea raster type the tie point is a pixel corner, so sample
//! positions are pixel centres (half a pixel in).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

use super::grid::Grid;
use super::{InputError, check_vertex_count};

/// GeoKey holding PixelIsArea (1) / PixelIsPoint (2).
const GT_RASTER_TYPE_GEO_KEY: u16 = 1025;
const RASTER_PIXEL_IS_POINT: u16 = 2;

pub(super) fn read(path: &Path, file: &str) -> Result<Grid, InputError> {
    let f = File::open(path).map_err(|e| InputError::io(file, e))?;
    let file_len = f.metadata().map_err(|e| InputError::io(file, e))?.len();
    let bad = |e: tiff::TiffError| match e {
        tiff::TiffError::UnsupportedError(u) => InputError::unsupported(file, format!("TIFF {u}")),
        e => InputError::malformed(file, format!("invalid TIFF: {e}")),
    };
    // The default 256 MiB buffer limit rejects ordinary 1 m DEM tiles;
    // 4 GiB still refuses absurd headers before allocating.
    let mut limits = Limits::default();
    limits.decoding_buffer_size = usize::try_from(4u64 << 30).unwrap_or(usize::MAX);
    limits.intermediate_buffer_size = 1 << 30;
    let mut decoder = Decoder::new(BufReader::new(f))
        .map_err(bad)?
        .with_limits(limits);
    let (width, height) = decoder.dimensions().map_err(bad)?;
    let (cols, rows) = (width as usize, height as usize);
    check_vertex_count(file, width as u64 * height as u64)?;
    let samples = decoder
        .find_tag_unsigned::<u16>(Tag::SamplesPerPixel)
        .map_err(bad)?
        .unwrap_or(1)
        .max(1) as usize;
    let planar = decoder
        .find_tag_unsigned::<u16>(Tag::PlanarConfiguration)
        .map_err(bad)?
        .unwrap_or(1)
        == 2;

    let f64_tag = |decoder: &mut Decoder<_>, tag| -> Result<Option<Vec<f64>>, InputError> {
        match decoder.find_tag(tag).map_err(bad)? {
            Some(v) => Ok(Some(v.into_f64_vec().map_err(bad)?)),
            None => Ok(None),
        }
    };
    let scale = f64_tag(&mut decoder, Tag::ModelPixelScaleTag)?;
    let tiepoint = f64_tag(&mut decoder, Tag::ModelTiepointTag)?;
    let transform = f64_tag(&mut decoder, Tag::ModelTransformationTag)?;
    let pixel_is_point = match decoder.find_tag(Tag::GeoKeyDirectoryTag).map_err(bad)? {
        Some(v) => {
            let keys = v.into_u16_vec().map_err(bad)?;
            keys.get(4..).unwrap_or(&[]).chunks_exact(4).any(|k| {
                k[0] == GT_RASTER_TYPE_GEO_KEY && k[1] == 0 && k[3] == RASTER_PIXEL_IS_POINT
            })
        }
        None => false,
    };
    // An ASCII value's length is the file's word: the tiff crate allocates
    // it whole before reading (4 GB of address space for a 162-byte file
    // that claims them), and above its buffer limit (BigTIFF counts) it
    // prints a debug line of its own beside our error, which fuzzing found.
    // A value cannot be longer than the file that holds it.
    if let Some(entry) = decoder.image_ifd().find_entry(Tag::GdalNodata)
        && entry.count() > file_len
    {
        return Err(InputError::malformed(
            file,
            format!(
                "GDAL_NODATA claims {} bytes, more than the file's {file_len}",
                entry.count()
            ),
        ));
    }
    let nodata = match decoder.find_tag(Tag::GdalNodata).map_err(bad)? {
        Some(v) => {
            let text = v.into_string().map_err(bad)?;
            let text = text.trim_matches(|c: char| c.is_whitespace() || c == '\0');
            Some(text.parse::<f64>().map_err(|_| {
                InputError::malformed(file, format!("GDAL_NODATA '{text}' is not a number"))
            })?)
        }
        None => None,
    };

    let image = decoder.read_image().map_err(bad)?;
    let all = to_f64(image);
    let stride = if planar { 1 } else { samples };
    let values: Vec<f64> = all
        .iter()
        .step_by(stride)
        .take(rows * cols)
        .copied()
        .collect();
    if values.len() != rows * cols {
        return Err(InputError::malformed(
            file,
            format!(
                "image holds {} samples, expected {rows} x {cols}",
                values.len()
            ),
        ));
    }

    // Raster (col, row) -> model (x, y) as x = x0 + col * sx, y = y0 - row * sy,
    // where (col, row) address pixel corners for PixelIsArea.
    let (georeferenced, x0, y0, sx, sy) = match (scale, tiepoint, transform) {
        (Some(s), Some(t), _) if s.len() >= 2 && t.len() >= 6 => {
            (true, t[3] - t[0] * s[0], t[4] + t[1] * s[1], s[0], s[1])
        }
        (_, _, Some(m)) if m.len() >= 8 => {
            if m[1] != 0.0 || m[4] != 0.0 {
                return Err(InputError::unsupported(
                    file,
                    "rotated or sheared ModelTransformationTag",
                ));
            }
            (true, m[3], m[7], m[0], -m[5])
        }
        (Some(s), None, _) if s.len() >= 2 => (false, 0.0, 0.0, s[0], s[1]),
        _ => (false, 0.0, 0.0, 1.0, 1.0),
    };
    // Without a tie point there is no model origin: put the south-west
    // sample at (0, 0).
    let half = if pixel_is_point { 0.0 } else { 0.5 };
    let (west, south) = if georeferenced {
        (
            x0 + half * sx,
            y0 - (rows.saturating_sub(1) as f64 + half) * sy,
        )
    } else {
        (0.0, 0.0)
    };
    if !(sx.is_finite() && sy.is_finite() && sx != 0.0 && sy != 0.0) {
        return Err(InputError::malformed(
            file,
            format!("invalid pixel scale {sx} x {sy}"),
        ));
    }
    Grid::from_north_first(rows, cols, values, [west, south], [sx, sy], nodata)
        .ok_or_else(|| InputError::malformed(file, "image size mismatch"))
}

fn to_f64(image: DecodingResult) -> Vec<f64> {
    fn widen<T: Copy + Into<f64>>(v: Vec<T>) -> Vec<f64> {
        v.into_iter().map(Into::into).collect()
    }
    match image {
        DecodingResult::U8(v) => widen(v),
        DecodingResult::U16(v) => widen(v),
        DecodingResult::U32(v) => widen(v),
        DecodingResult::U64(v) => v.into_iter().map(|x| x as f64).collect(),
        DecodingResult::F16(v) => v.into_iter().map(|x| x.to_f64()).collect(),
        DecodingResult::F32(v) => widen(v),
        DecodingResult::F64(v) => v,
        DecodingResult::I8(v) => widen(v),
        DecodingResult::I16(v) => widen(v),
        DecodingResult::I32(v) => widen(v),
        DecodingResult::I64(v) => v.into_iter().map(|x| x as f64).collect(),
    }
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;

    use tiff::encoder::{TiffEncoder, colortype};

    use super::super::test_util::TempFile;
    use super::super::{ReadOptions, check_mesh, read_mesh};
    use super::*;

    /// 3 columns x 2 rows; row 0 (north) = [1, 2, 3].
    fn write<C: colortype::ColorType>(data: &[C::Inner], geo: bool, nodata: Option<&str>) -> Vec<u8>
    where
        [C::Inner]: tiff::encoder::TiffValue,
    {
        let mut buf = Cursor::new(Vec::new());
        let mut enc = TiffEncoder::new(&mut buf).unwrap();
        let mut image = enc.new_image::<C>(3, 2).unwrap();
        if geo {
            image
                .encoder()
                .write_tag(Tag::ModelPixelScaleTag, &[10.0f64, 20.0, 0.0][..])
                .unwrap();
            image
                .encoder()
                .write_tag(
                    Tag::ModelTiepointTag,
                    &[0.0f64, 0.0, 0.0, 1000.0, 5000.0, 0.0][..],
                )
                .unwrap();
        }
        if let Some(nd) = nodata {
            image.encoder().write_tag(Tag::GdalNodata, nd).unwrap();
        }
        image.write_data(data).unwrap();
        buf.into_inner()
    }

    #[test]
    fn reads_sample_types_and_georeferencing() {
        let cases = [
            write::<colortype::Gray32Float>(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], true, None),
            write::<colortype::Gray64Float>(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], true, None),
            write::<colortype::GrayI16>(&[1, 2, 3, 4, 5, 6], true, None),
            write::<colortype::Gray16>(&[1, 2, 3, 4, 5, 6], true, None),
            write::<colortype::GrayI32>(&[1, 2, 3, 4, 5, 6], true, None),
        ];
        for (i, bytes) in cases.iter().enumerate() {
            let f = TempFile::new("dem.tif", bytes);
            let g = read(&f.0, "dem.tif").unwrap();
            assert_eq!(g.elevations, vec![4.0, 5.0, 6.0, 1.0, 2.0, 3.0], "case {i}");
            assert_eq!(g.spacing, [10.0, 20.0]);
            // Pixel centres: west = 1000 + 5, south row centre = 5000 - 1.5 * 20.
            assert_eq!(g.origin, [1005.0, 4970.0]);
            let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
            assert!(m.positions.contains(&[1005.0, 4990.0, 1.0]));
            check_mesh(&m).unwrap();
        }
    }

    /// A 2 x 2 float TIFF whose GDAL_NODATA entry claims `count` bytes at
    /// offset 100 (past the end): BigTIFF when `big`, for counts beyond
    /// 32 bits.
    fn nodata_claiming(count: u64, big: bool) -> Vec<u8> {
        let data: Vec<u8> = [1.0f32, 2.0, 3.0, 4.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let start = if big { 16 } else { 8 };
        // (tag, type, count, value): 3 SHORT, 4 LONG, 16 LONG8, 2 ASCII.
        let offsets = if big { 16 } else { 4 };
        let entries: [(u16, u16, u64, u64); 11] = [
            (256, 3, 1, 2),
            (257, 3, 1, 2),
            (258, 3, 1, 32),
            (259, 3, 1, 1),
            (262, 3, 1, 1),
            (273, offsets, 1, start),
            (277, 3, 1, 1),
            (278, 3, 1, 2),
            (279, offsets, 1, data.len() as u64),
            (339, 3, 1, 3),
            (42113, 2, count, 100),
        ];
        let mut out = Vec::new();
        if big {
            out.extend(b"II+\0\x08\0\0\0");
            out.extend((start + data.len() as u64).to_le_bytes());
        } else {
            out.extend(b"II*\0");
            out.extend((start as u32 + data.len() as u32).to_le_bytes());
        }
        out.extend(&data);
        if big {
            out.extend((entries.len() as u64).to_le_bytes());
        } else {
            out.extend((entries.len() as u16).to_le_bytes());
        }
        for (tag, kind, count, value) in entries {
            out.extend(tag.to_le_bytes());
            out.extend(kind.to_le_bytes());
            if big {
                out.extend(count.to_le_bytes());
                out.extend(value.to_le_bytes());
            } else {
                out.extend((count as u32).to_le_bytes());
                out.extend((value as u32).to_le_bytes());
            }
        }
        out.extend(if big { &[0u8; 8][..] } else { &[0u8; 4][..] });
        out
    }

    #[test]
    fn a_nodata_string_longer_than_the_file_is_refused_before_it_is_read() {
        // Classic TIFF claiming nearly 4 GB (allocated whole before), and a
        // BigTIFF claiming a terabyte (the tiff crate's own debug print).
        for (count, big) in [(0xFFFF_FFF0, false), (1 << 40, true)] {
            let bytes = nodata_claiming(count, big);
            let f = TempFile::new("huge-nodata.tif", &bytes);
            let err = read(&f.0, "huge-nodata.tif").unwrap_err().to_string();
            assert!(
                err.contains(&format!(
                    "GDAL_NODATA claims {count} bytes, more than the file's {}",
                    bytes.len()
                )),
                "{err}"
            );
        }
        // The same layout with a count that fits reads past the end: the
        // tiff crate's own error, not this one.
        let bytes = nodata_claiming(8, false);
        let f = TempFile::new("short-nodata.tif", &bytes);
        let err = read(&f.0, "short-nodata.tif").unwrap_err().to_string();
        assert!(!err.contains("claims"), "{err}");
    }

    #[test]
    fn plain_tiff_and_nodata() {
        let bytes = write::<colortype::Gray32Float>(
            &[1.0, -9999.0, 3.0, 4.0, 5.0, 6.0],
            false,
            Some("-9999"),
        );
        let f = TempFile::new("plain.tiff", &bytes);
        let g = read(&f.0, "plain.tiff").unwrap();
        assert_eq!(g.spacing, [1.0, 1.0]);
        assert_eq!(g.origin, [0.0, 0.0]);
        assert_eq!(g.nodata, Some(-9999.0));
        // The missing sample takes 3 of the 4 triangles with it.
        let m = read_mesh(&f.0, &ReadOptions::default()).unwrap();
        assert_eq!(m.positions.len(), 3);
        assert_eq!(m.triangles.len(), 1);
        check_mesh(&m).unwrap();
    }

    #[test]
    fn rgb_takes_first_band_and_garbage_fails() {
        let mut buf = Cursor::new(Vec::new());
        let mut enc = TiffEncoder::new(&mut buf).unwrap();
        enc.write_image::<colortype::RGB8>(
            2,
            2,
            &[1, 100, 100, 2, 100, 100, 3, 100, 100, 4, 100, 100],
        )
        .unwrap();
        let f = TempFile::new("rgb.tif", &buf.into_inner());
        let g = read(&f.0, "rgb.tif").unwrap();
        assert_eq!(g.elevations, vec![3.0, 4.0, 1.0, 2.0]);

        let good = write::<colortype::Gray32Float>(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], true, None);
        for cut in [4, 16, good.len() - 4] {
            let f = TempFile::new("cut.tif", &good[..cut]);
            let msg = read(&f.0, "cut.tif").unwrap_err().to_string();
            assert!(msg.starts_with("cut.tif: ") && !msg.contains('\n'), "{msg}");
        }
    }
}
