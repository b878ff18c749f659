//! Rays per second, from a frame's ray counts and the time of its passes.

/// All, camera and shadow rays per second of a frame of `seconds` whose primary pass took
/// `primary_seconds` (NaN where the clock cannot time passes apart): all rays over the frame,
/// camera rays over the primary pass, shadow rays over the rest.
pub fn rays_per_second(primary_rays: f64, shadow_rays: f64, seconds: f64, primary_seconds: f64) -> [f64; 3] {
    [
        (primary_rays + shadow_rays) / seconds,
        primary_rays / primary_seconds,
        shadow_rays / (seconds - primary_seconds),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_are_timed_apart_only_where_the_clock_splits_them() {
        assert_eq!(rays_per_second(100.0, 300.0, 2.0, 0.5), [200.0, 200.0, 200.0]);
        let [all, primary, shadow] = rays_per_second(100.0, 300.0, 2.0, f64::NAN);
        assert_eq!(all, 200.0);
        assert!(primary.is_nan() && shadow.is_nan());
    }
}
