//! How many levels a viewer needs: a level's screen-space error is its
//! geometric error (decoder-core SPEC §4.1, the encoder's estimate in model
//! units) projected at the object's distance. A client decodes levels up to
//! the coarsest one whose error covers at most `max_pixels` pixels, the
//! rule 3D Tiles and quantized-mesh viewers use for their tiles.

use core::fmt;

/// A perspective camera's vertical extent: what turns a model-space length
/// at some distance into pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenView {
    /// Pixels covered by one model unit at distance 1: the viewport height
    /// over `2 tan(fov_y / 2)`.
    scale: f32,
}

impl ScreenView {
    /// A camera with a viewport `viewport_height` pixels high and a
    /// vertical field of view of `fov_y` radians (strictly between 0 and π).
    pub fn perspective(viewport_height: f32, fov_y: f32) -> Result<ScreenView, ViewError> {
        if !(viewport_height.is_finite() && viewport_height > 0.0) {
            return Err(ViewError::ViewportHeight(viewport_height));
        }
        if !(fov_y > 0.0 && fov_y < core::f32::consts::PI) {
            return Err(ViewError::FieldOfView(fov_y));
        }
        ScreenView::from_scale(viewport_height / (2.0 * (fov_y / 2.0).tan()))
    }

    /// A camera given by its scale, the pixels one model unit covers at
    /// distance 1 (for a projection matrix `P`, the viewport height times
    /// `P[1][1] / 2`).
    pub fn from_scale(scale: f32) -> Result<ScreenView, ViewError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(ViewError::Scale(scale));
        }
        Ok(ScreenView { scale })
    }

    /// Pixels one model unit covers at distance 1.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// The model-space error that covers `pixels` pixels at `distance`
    /// (model units from the camera, at least 0).
    pub fn error_for_pixels(&self, pixels: f32, distance: f32) -> Result<f32, ViewError> {
        if !(pixels.is_finite() && pixels > 0.0) {
            return Err(ViewError::Pixels(pixels));
        }
        if !(distance.is_finite() && distance >= 0.0) {
            return Err(ViewError::Distance(distance));
        }
        Ok(pixels * distance / self.scale)
    }
}

/// A view parameter that cannot describe a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewError {
    /// Not a finite number of pixels above 0.
    ViewportHeight(f32),
    /// Not strictly between 0 and π radians.
    FieldOfView(f32),
    /// Not a finite scale above 0.
    Scale(f32),
    /// Not a finite distance of at least 0.
    Distance(f32),
    /// Not a finite error above 0 pixels.
    Pixels(f32),
    /// A model-space error bound that is NaN or below 0
    /// (`Session::checked_level_within_error`).
    MaxError(f32),
}

impl fmt::Display for ViewError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ViewError::ViewportHeight(v) => {
                write!(f, "viewport height {v} is not a number of pixels above 0")
            }
            ViewError::FieldOfView(v) => {
                write!(
                    f,
                    "field of view {v} is not strictly between 0 and pi radians"
                )
            }
            ViewError::Scale(v) => write!(f, "projection scale {v} is not a finite number above 0"),
            ViewError::Distance(v) => {
                write!(f, "distance {v} is not a finite number of at least 0")
            }
            ViewError::Pixels(v) => write!(
                f,
                "screen-space error {v} is not a finite number of pixels above 0"
            ),
            ViewError::MaxError(v) => write!(
                f,
                "error bound {v} is not a number of model units of at least 0"
            ),
        }
    }
}

impl std::error::Error for ViewError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ninety_degree_view_covers_half_its_height_at_distance_one() {
        // tan(45°) = 1: one unit at distance 1 covers half the viewport.
        let view = ScreenView::perspective(1000.0, core::f32::consts::FRAC_PI_2).unwrap();
        assert!((view.scale() - 500.0).abs() < 1e-3);
        let error = view.error_for_pixels(2.0, 250.0).unwrap();
        assert!((error - 1.0).abs() < 1e-5, "{error}");
        assert_eq!(view.error_for_pixels(2.0, 0.0), Ok(0.0));
    }

    #[test]
    fn bad_parameters_are_named() {
        let pi = core::f32::consts::PI;
        assert_eq!(
            ScreenView::perspective(0.0, 1.0),
            Err(ViewError::ViewportHeight(0.0))
        );
        assert_eq!(
            ScreenView::perspective(900.0, pi),
            Err(ViewError::FieldOfView(pi))
        );
        assert!(matches!(
            ScreenView::perspective(900.0, f32::NAN),
            Err(ViewError::FieldOfView(_))
        ));
        assert_eq!(ScreenView::from_scale(-1.0), Err(ViewError::Scale(-1.0)));
        let view = ScreenView::from_scale(100.0).unwrap();
        assert_eq!(view.error_for_pixels(0.0, 1.0), Err(ViewError::Pixels(0.0)));
        assert_eq!(
            view.error_for_pixels(1.0, -2.0),
            Err(ViewError::Distance(-2.0))
        );
        assert!(matches!(
            view.error_for_pixels(1.0, f32::INFINITY),
            Err(ViewError::Distance(_))
        ));
        assert_eq!(
            ViewError::FieldOfView(4.0).to_string(),
            "field of view 4 is not strictly between 0 and pi radians"
        );
    }
}
