//! A part of a frame-time experiment's scene moved by a fixed step every frame (`[motion]`), each
//! structure updated before each frame.

use super::scenes::Generator;
use crate::accel::AccelSettings;
use crate::config::{ConfigError, Seg, Source};
use crate::key_path;
use crate::scene::load::MAX_EXTENT;
use glam::DVec3;

/// A part moved by a fixed step every frame, each structure updated in its own way.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// The moving part's name.
    pub part: String,
    /// Translation per frame, metres.
    pub step: DVec3,
}

impl Motion {
    /// `[motion]`'s `part` of `generator`'s scenes moved by `step` each frame, checked.
    pub fn read(source: &Source, generator: &Generator, part: &str, step: [f64; 3]) -> Result<Motion, ConfigError> {
        let err = |p: &[Seg], m: String| source.error(p, m);
        let probe = generator.probe();
        if probe.part(part).is_none() {
            let names: Vec<&str> = probe.parts.iter().map(|p| p.name.as_str()).collect();
            return Err(err(
                &key_path!["motion", "part"],
                format!("no part `{part}`; the scene has: {}", names.join(", ")),
            ));
        }
        let step = DVec3::from_array(step);
        if !step.is_finite() {
            return Err(err(&key_path!["motion", "step"], "coordinates must be finite".into()));
        }
        Ok(Motion {
            part: part.to_string(),
            step,
        })
    }

    /// The part stays within the coordinates any scene may reach over `frames` frames, and inside
    /// the ball each of `structures` that can follow it only there is built in, in every scene.
    pub fn check_travel(
        &self,
        source: &Source,
        frames: u32,
        structures: &[AccelSettings],
        generator: &Generator,
    ) -> Result<(), ConfigError> {
        let m = self;
        let travel = m.step * frames as f64;
        let too_far = |why: String| {
            let moved = format!("over {frames} frames `{}` travels {:?} m", m.part, travel.to_array());
            Err(source.error(&key_path!["motion", "step"], format!("{moved}{why}: shorten the step")))
        };
        let far = travel.abs().max_element();
        if far.is_nan() || far > MAX_EXTENT {
            return too_far(format!(", beyond the +-{MAX_EXTENT:e} m any coordinate may reach"));
        }
        let bounded: Vec<_> = structures
            .iter()
            .filter_map(|s| Some((s.name, crate::accel::registered(s.name)?.follows_within?)))
            .collect();
        if bounded.is_empty() {
            return Ok(());
        }
        for g in (0..generator.count()).map(|i| generator.scene(i)) {
            let t = g.triangles();
            let (index, _) = g.part(&m.part).expect("validated part");
            for (name, within) in &bounded {
                let (centre, radius) = within(&t.positions);
                let out = t
                    .positions
                    .iter()
                    .zip(&t.object_of)
                    .filter(|(_, &o)| o as usize == index)
                    .flat_map(|(p, _)| p.iter())
                    .map(|p| (*p + travel).distance(centre))
                    .fold(0.0, f64::max);
                if out > radius {
                    return too_far(format!(
                        " and leaves the ball `{name}` is built in ({out:.3} m from its centre, radius {radius:.3} m), where it cannot follow"
                    ));
                }
            }
        }
        Ok(())
    }
}
