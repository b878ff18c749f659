//! Shadow-ray targets exactly on the rim of the disk light: they land at exactly the light's
//! radius, are traced like any other target, and see what the exact reference sees there.

use glam::{DVec2, DVec3};
use penumbra::reference::visibility::is_visible;
use penumbra::render::shading::{shade_light, Receiver, Targets};
use penumbra::render::NO_HIT;
use penumbra::scene::{DiskLight, Light, Plane, Scene, Sphere};

#[test]
fn rim_targets_are_traced_and_agree_with_the_exact_test() {
    let light = DiskLight {
        center: DVec3::new(0.0, 0.0, 2.0),
        normal: DVec3::NEG_Z,
        radius: 0.5,
        power: 10.0,
        samples: 64,
    };
    let sphere = Sphere {
        center: DVec3::new(0.0, 0.0, 1.0),
        radius: 0.3,
        albedo: 0.5,
    };
    let plane = Plane {
        point: DVec3::ZERO,
        normal: DVec3::Z,
        albedo: 0.5,
    };
    let scene = Scene::analytic(vec![sphere], vec![plane], vec![Light::Disk(light.clone())]);
    // 64 points exactly on the unit circle (cos^2 + sin^2 rounds to 1 within an ulp).
    let rim: Vec<DVec2> = (0..64)
        .map(|k| DVec2::from_angle(k as f64 * std::f64::consts::TAU / 64.0))
        .collect();
    let (u, v) = light.basis();
    let mut partial = 0;
    for x in [0.0, 0.2, 0.45, 0.6, 0.9] {
        let p = DVec3::new(x, 0.0, 0.0);
        let receiver = Receiver {
            p,
            n: DVec3::Z,
            albedo: 0.5,
            object: scene.plane(0).unwrap().0,
            triangle: NO_HIT,
        };
        let s = shade_light(&scene, &receiver, &scene.lights[0], Targets::Shared(&rim));
        assert_eq!(s.rays, 64, "every rim target is in front of the receiver and traced");
        let expected = rim
            .iter()
            .filter(|t| {
                let q = light.center + light.radius * (t.x * u + t.y * v);
                assert!(((q - light.center).length() - light.radius).abs() < 1e-15);
                is_visible(p, DVec3::Z, q, std::slice::from_ref(&sphere), &[])
            })
            .count();
        assert_eq!((s.visibility * 64.0).round() as usize, expected, "x = {x}");
        partial += (expected > 0 && expected < 64) as usize;
    }
    assert!(partial >= 2, "the receivers must see the rim partly occluded");
}
