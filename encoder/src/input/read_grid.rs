//! Reading an elevation grid as a grid (not as a mesh), for consumers that
//! work on the raster itself, such as the grid-tile simplifier.

use std::path::Path;

use super::{GRID_EXTENSIONS, Grid, InputError, ReadOptions, esri, geotiff, npy};

/// Reads a `.tif`/`.tiff`, `.asc`, `.npy` or `.npz` elevation grid (chosen
/// by extension, case-insensitive), applying `options.grid_spacing` and
/// `options.z_scale`. Rows run south to north as in [`Grid`]. Mesh formats
/// and unknown extensions give [`InputError::UnknownExtension`].
pub fn read_grid(path: &Path, options: &ReadOptions) -> Result<Grid, InputError> {
    let file = path.display().to_string();
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut grid = match extension.as_str() {
        "tif" | "tiff" => geotiff::read(path, &file)?,
        "asc" => esri::read(path, &file)?,
        "npy" => npy::read_npy(path, &file)?,
        "npz" => npy::read_npz(path, &file, options.npz_array.as_deref())?,
        _ => {
            return Err(InputError::UnknownExtension {
                file,
                extension,
                supported: GRID_EXTENSIONS,
            });
        }
    };
    grid = super::apply_spacing(grid, options);
    if options.z_scale != 1.0 {
        for z in &mut grid.elevations {
            *z *= options.z_scale;
        }
    }
    Ok(grid)
}
