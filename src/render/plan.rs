//! The render plan: which passes and how many rays a scene calls for, derived from the scene
//! rather than fixed in a shader ("simulate only the effects a scene calls for").

use super::View;
use crate::scene::{Light, Scene};
use serde::Serialize;
use std::fmt;

pub use crate::scene::MAX_LIGHTS;

/// One pass of the plan.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "pass", rename_all = "kebab-case")]
pub enum Pass {
    /// Camera rays against the scene's shapes: closest hit.
    Primary {
        /// One ray per pixel.
        rays: u64,
        /// Shape kinds intersected (only those present in the scene); meshes name the
        /// acceleration structure that answers for them.
        shapes: Vec<String>,
    },
    /// Shadow rays from every receiver point towards one light: any-hit with early exit.
    Shadow {
        /// Light index in the scene.
        light: usize,
        /// `point` or `disk`.
        kind: &'static str,
        /// Rays per receiver point that faces the light (1 for a point light).
        rays_per_receiver: u32,
        /// Upper bound on rays: receivers facing away from the light issue none.
        max_rays: u64,
    },
    /// Local shading from every light without occlusion tests (OpenGL-like): no rays. Replaces
    /// the shadow passes where the scene's shading has no shadows.
    Direct {
        /// Lights shaded.
        lights: usize,
    },
    /// Whitted's mirror chains: from every receiver with a mirror weight, the reflected ray's
    /// closest hit and, at each vertex reached, local shading from every light (with shadow rays
    /// where the scene has shadows), up to `max_depth` bounces. Only where the scene asks for
    /// reflections and has a mirror.
    Mirror {
        /// Most bounces per camera ray.
        max_depth: u32,
        /// Rays per bounce at most: the reflected ray and the shadow rays of its vertex.
        rays_per_bounce: u64,
        /// Rays if every pixel saw a perfect mirror chain of full depth.
        max_rays: u64,
    },
    /// Ambient-occlusion rays from every receiver point into its hemisphere: any-hit with early
    /// exit, up to the scene's maximum distance. Only where the scene asks for it.
    Ambient {
        /// Where the directions come from, in a few words.
        directions: String,
        /// `plain` or `cosine`.
        weighting: &'static str,
        /// Rays per receiver point.
        rays_per_receiver: u32,
        /// Rays if every pixel sees a receiver.
        max_rays: u64,
    },
}

impl Pass {
    /// The pass's name, as serialised.
    pub fn name(&self) -> &'static str {
        match self {
            Pass::Primary { .. } => "primary",
            Pass::Shadow { .. } => "shadow",
            Pass::Direct { .. } => "direct",
            Pass::Mirror { .. } => "mirror",
            Pass::Ambient { .. } => "ambient",
        }
    }
}

/// The passes one frame runs, in order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderPlan {
    /// Passes in execution order.
    pub passes: Vec<Pass>,
}

impl RenderPlan {
    /// The plan for `scene` seen through `view`: a primary pass over the shapes the scene has,
    /// then one shadow pass per light with that light's ray count (or one unoccluded direct pass
    /// where the scene has no shadows), then mirror chains and ambient occlusion where the scene
    /// asks for them; nothing else.
    pub fn new(scene: &Scene, view: View) -> anyhow::Result<RenderPlan> {
        anyhow::ensure!(
            scene.lights.len() <= MAX_LIGHTS,
            "the scene has {} lights; at most {MAX_LIGHTS} are supported",
            scene.lights.len()
        );
        let pixels = view.pixels() as u64;
        let mut shapes = Vec::new();
        for kind in ["sphere", "plane"] {
            if scene.shapes.iter().any(|s| s.kind() == kind) {
                shapes.push(kind.to_string());
            }
        }
        if let Some(a) = &scene.accel {
            shapes.push(format!("mesh ({})", a.name().to_uppercase()));
        }
        let mut passes = vec![Pass::Primary { rays: pixels, shapes }];
        let shadows = scene.shading.shadows;
        if !shadows && !scene.lights.is_empty() {
            passes.push(Pass::Direct {
                lights: scene.lights.len(),
            });
        }
        for (i, light) in scene.lights.iter().enumerate().filter(|_| shadows) {
            let n = light.samples();
            passes.push(Pass::Shadow {
                light: i,
                kind: match light {
                    Light::Point { .. } => "point",
                    Light::Disk(_) => "disk",
                },
                rays_per_receiver: n,
                max_rays: pixels * n as u64,
            });
        }
        let depth = scene.shading.mirror_depth;
        if depth > 0 && scene.has_mirrors() {
            let shadow_rays: u64 = if shadows {
                scene.lights.iter().map(|l| l.samples() as u64).sum()
            } else {
                0
            };
            passes.push(Pass::Mirror {
                max_depth: depth,
                rays_per_bounce: 1 + shadow_rays,
                max_rays: pixels * depth as u64 * (1 + shadow_rays),
            });
        }
        if let Some(a) = &scene.ambient {
            passes.push(Pass::Ambient {
                directions: a.directions.describe(),
                weighting: a.weighting.name(),
                rays_per_receiver: a.rays,
                max_rays: pixels * a.rays as u64,
            });
        }
        Ok(RenderPlan { passes })
    }

    /// Most rays a frame can trace.
    pub fn max_rays(&self) -> u64 {
        self.passes
            .iter()
            .map(|p| match p {
                Pass::Primary { rays, .. } => *rays,
                Pass::Shadow { max_rays, .. } | Pass::Ambient { max_rays, .. } | Pass::Mirror { max_rays, .. } => {
                    *max_rays
                }
                Pass::Direct { .. } => 0,
            })
            .sum()
    }
}

impl fmt::Display for RenderPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for p in &self.passes {
            match p {
                Pass::Primary { rays, shapes } => writeln!(f, "primary: {rays} rays vs [{}]", shapes.join(", "))?,
                Pass::Shadow {
                    light,
                    kind,
                    rays_per_receiver,
                    max_rays,
                } => writeln!(
                    f,
                    "shadow light {light} ({kind}): {rays_per_receiver} rays/receiver, <= {max_rays} rays"
                )?,
                Pass::Direct { lights } => writeln!(f, "direct light from {lights} lights, unoccluded: no rays")?,
                Pass::Mirror {
                    max_depth,
                    rays_per_bounce,
                    max_rays,
                } => writeln!(
                    f,
                    "mirror chains: <= {max_depth} bounces of {rays_per_bounce} rays, <= {max_rays} rays"
                )?,
                Pass::Ambient {
                    directions,
                    weighting,
                    rays_per_receiver,
                    max_rays,
                } => writeln!(
                    f,
                    "ambient occlusion ({directions}, {weighting}): {rays_per_receiver} rays/receiver, <= {max_rays} rays"
                )?,
            }
        }
        Ok(())
    }
}
