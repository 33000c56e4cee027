//! One-dimensional coordinate arrays beside a `.npz` raster: the x of each
//! column and the y of each row, as `np.savez(f, topo=z, longitude=lon,
//! latitude=lat)` or an xarray dataset's coordinates write them
//! (matplotlib's `topobathy.npz` does). Without them the samples would sit
//! at unit spacing from 0, and `--geographic` would read those indices as
//! degrees.

use super::InputError;

/// Names of an x coordinate array (compared without case).
pub(super) const X_NAMES: [&str; 7] = [
    "x",
    "lon",
    "lons",
    "longitude",
    "longitudes",
    "easting",
    "eastings",
];

/// Names of a y coordinate array (compared without case).
pub(super) const Y_NAMES: [&str; 7] = [
    "y",
    "lat",
    "lats",
    "latitude",
    "latitudes",
    "northing",
    "northings",
];

/// How far from even steps, as a fraction of the mean step, a listed axis
/// still counts as regular: coordinates stored as f32 (topobathy's
/// longitudes, 234–238° in steps of 1/30°) are 0.3 % of a step off.
const REGULAR_WITHIN: f64 = 0.01;

/// Positions along one axis of the grid, from its coordinate array.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Axis {
    /// Evenly spaced: the first sample and the step (negative where the
    /// array decreases).
    Regular { first: f64, step: f64 },
    /// Unevenly spaced: every sample's coordinate, strictly monotonic.
    Listed(Vec<f64>),
}

impl Axis {
    /// The first coordinate and the mean step.
    pub(super) fn first_and_step(&self) -> (f64, f64) {
        match self {
            Axis::Regular { first, step } => (*first, *step),
            Axis::Listed(v) => (v[0], (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64),
        }
    }

    /// Every coordinate of `count` samples.
    pub(super) fn values(&self, count: usize) -> Vec<f64> {
        match self {
            Axis::Regular { first, step } => (0..count).map(|i| first + i as f64 * step).collect(),
            Axis::Listed(v) => v.clone(),
        }
    }
}

/// The name among `names` (other than `raster`) that is one of `wanted`.
pub(super) fn find<'a>(names: &'a [String], wanted: &[&str], raster: &str) -> Option<&'a str> {
    names
        .iter()
        .filter(|n| n.as_str() != raster)
        .find(|n| wanted.iter().any(|w| n.eq_ignore_ascii_case(w)))
        .map(String::as_str)
}

/// Checks array `name` as the coordinates of the grid's `count` columns or
/// rows (`what`): one finite value each, strictly increasing or strictly
/// decreasing.
pub(super) fn axis(
    file: &str,
    name: &str,
    values: Vec<f64>,
    count: usize,
    what: &str,
) -> Result<Axis, InputError> {
    if values.len() != count {
        return Err(InputError::malformed(
            file,
            format!(
                "coordinate array '{name}' has {} values for the grid's {count} {what}",
                values.len()
            ),
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(InputError::malformed(
            file,
            format!("coordinate array '{name}': value {i} is {}", values[i]),
        ));
    }
    if count < 2 {
        return Ok(Axis::Regular {
            first: values.first().copied().unwrap_or(0.0),
            step: 1.0,
        });
    }
    let increasing = values[1] > values[0];
    if let Some(i) = values.windows(2).position(|w| {
        if increasing {
            w[1] <= w[0]
        } else {
            w[1] >= w[0]
        }
    }) {
        return Err(InputError::malformed(
            file,
            format!(
                "coordinate array '{name}' is not monotonic: value {} is {} after {}",
                i + 1,
                values[i + 1],
                values[i]
            ),
        ));
    }
    let first = values[0];
    let step = (values[count - 1] - first) / (count - 1) as f64;
    let off = values
        .iter()
        .enumerate()
        .map(|(i, v)| (v - (first + i as f64 * step)).abs())
        .fold(0.0f64, f64::max);
    if off <= REGULAR_WITHIN * step.abs() {
        Ok(Axis::Regular { first, step })
    } else {
        Ok(Axis::Listed(values))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_steps_are_regular_within_f32_rounding() {
        let lon: Vec<f64> = (0..120)
            .map(|i| f64::from((234.0167f64 + i as f64 / 30.0) as f32))
            .collect();
        let Axis::Regular { first, step } = axis("f", "longitude", lon, 120, "columns").unwrap()
        else {
            panic!("not regular");
        };
        assert!((first - 234.0167).abs() < 1e-4 && (step - 1.0 / 30.0).abs() < 1e-6);
        let down = axis("f", "lat", vec![3.0, 2.0, 1.0], 3, "rows").unwrap();
        assert_eq!(
            down,
            Axis::Regular {
                first: 3.0,
                step: -1.0
            }
        );
    }

    #[test]
    fn uneven_steps_are_listed() {
        let lat = vec![48.0, 48.5, 49.2, 50.1];
        assert_eq!(
            axis("f", "latitude", lat.clone(), 4, "rows").unwrap(),
            Axis::Listed(lat.clone())
        );
        let (first, step) = Axis::Listed(lat).first_and_step();
        assert!(first == 48.0 && (step - 0.7).abs() < 1e-12);
    }

    #[test]
    fn a_bad_axis_is_named() {
        let e = |values: Vec<f64>| {
            axis("f.npz", "lat", values, 3, "rows")
                .unwrap_err()
                .to_string()
        };
        assert!(e(vec![1.0, 2.0]).contains("'lat' has 2 values for the grid's 3 rows"));
        assert!(e(vec![1.0, f64::NAN, 3.0]).contains("value 1 is NaN"));
        assert!(e(vec![1.0, 3.0, 2.0]).contains("not monotonic: value 2 is 2 after 3"));
    }

    #[test]
    fn names_are_found_without_case() {
        let names: Vec<String> = ["topo", "Longitude", "LAT"].map(String::from).to_vec();
        assert_eq!(find(&names, &X_NAMES, "topo"), Some("Longitude"));
        assert_eq!(find(&names, &Y_NAMES, "topo"), Some("LAT"));
        assert_eq!(find(&names, &Y_NAMES, "LAT"), None);
    }
}
