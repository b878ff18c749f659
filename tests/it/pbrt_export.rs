//! The pbrt-v4 export read back by an interpreter of the directives it writes, built from
//! pbrt-v4's definitions (LookAt's left-handed frame, `Transform` given transposed, the screen
//! window and raster mapping of its projective cameras) and not from the exporter's code: every
//! pixel's camera ray, the disk's placement and orientation, the emitted radiance and the
//! transport settings must be penumbra's.

use crate::common;
use glam::{DMat4, DVec3, DVec4};
use penumbra::scene::{Light, Scene, Shape};
use std::path::Path;
use std::process::Command;

/// One token of a pbrt file: a bare word or number, a quoted string, or a bracket.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Word(String),
    Quoted(String),
    Open,
    Close,
}

fn tokens(text: &str) -> Vec<Token> {
    let mut out = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '#' => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        break;
                    }
                }
            }
            '[' => out.push(Token::Open),
            ']' => out.push(Token::Close),
            '"' => out.push(Token::Quoted(chars.by_ref().take_while(|&c| c != '"').collect())),
            c if c.is_whitespace() => {}
            c => {
                let mut w = c.to_string();
                while let Some(&n) = chars.peek() {
                    if n.is_whitespace() || matches!(n, '[' | ']' | '"' | '#') {
                        break;
                    }
                    w.push(n);
                    chars.next();
                }
                out.push(Token::Word(w));
            }
        }
    }
    out
}

/// A directive: its name, its leading arguments (numbers or a quoted type) and its parameter
/// list ("type name" -> values).
#[derive(Debug, Default)]
struct Directive {
    name: String,
    args: Vec<Token>,
    params: Vec<(String, Vec<Token>)>,
}

impl Directive {
    fn numbers(&self) -> Vec<f64> {
        self.args
            .iter()
            .filter_map(|t| match t {
                Token::Word(w) => Some(w.parse().unwrap()),
                _ => None,
            })
            .collect()
    }
    fn kind(&self) -> &str {
        match self.args.first() {
            Some(Token::Quoted(q)) => q,
            other => panic!("{}: no type, {other:?}", self.name),
        }
    }
    fn param(&self, typed_name: &str) -> &[Token] {
        &self
            .params
            .iter()
            .find(|(n, _)| n == typed_name)
            .unwrap_or_else(|| panic!("{} has no {typed_name}: {:?}", self.name, self.params))
            .1
    }
    fn floats(&self, typed_name: &str) -> Vec<f64> {
        self.param(typed_name)
            .iter()
            .map(|t| match t {
                Token::Word(w) => w.parse().unwrap(),
                other => panic!("{typed_name}: {other:?}"),
            })
            .collect()
    }
    fn word(&self, typed_name: &str) -> String {
        match self.param(typed_name) {
            [Token::Word(w)] | [Token::Quoted(w)] => w.clone(),
            other => panic!("{typed_name}: {other:?}"),
        }
    }
}

fn directives(text: &str) -> Vec<Directive> {
    let mut out: Vec<Directive> = Vec::new();
    let mut t = tokens(text).into_iter().peekable();
    while let Some(tok) = t.next() {
        match tok {
            Token::Word(w) if w.chars().next().unwrap().is_ascii_uppercase() => {
                out.push(Directive {
                    name: w,
                    ..Directive::default()
                });
            }
            Token::Quoted(q) if q.contains(' ') => {
                let mut values = Vec::new();
                match t.next().unwrap() {
                    Token::Open => {
                        for v in t.by_ref() {
                            if v == Token::Close {
                                break;
                            }
                            values.push(v);
                        }
                    }
                    single => values.push(single),
                }
                out.last_mut().unwrap().params.push((q, values));
            }
            Token::Open | Token::Close => {}
            other => out.last_mut().unwrap().args.push(other),
        }
    }
    out
}

/// pbrt-v4's LookAt: the camera-from-world matrix of a left-handed frame whose x axis is
/// up x forward.
fn look_at(pos: DVec3, look: DVec3, up: DVec3) -> DMat4 {
    let dir = (look - pos).normalize();
    let right = up.normalize().cross(dir).normalize();
    let new_up = dir.cross(right);
    DMat4::from_cols(right.extend(0.0), new_up.extend(0.0), dir.extend(0.0), pos.extend(1.0)).inverse()
}

/// A shape as pbrt's graphics state leaves it: its transform, the material and area light
/// current when it was declared (pbrt binds both at `Shape`, scoped by attribute blocks).
struct Bound {
    shape: Directive,
    transform: DMat4,
    material: Option<std::rc::Rc<Directive>>,
    area_light: Option<std::rc::Rc<Directive>>,
}

/// A scene exported to pbrt and interpreted: the world-from-camera matrix, the camera's kind,
/// screen window and fov, the shapes with their state, and the other world directives.
struct Interpreted {
    world_from_camera: DMat4,
    camera: Directive,
    film: Directive,
    shapes: Vec<Bound>,
    world: Vec<Directive>,
    others: Vec<Directive>,
}

fn interpret(text: &str) -> Interpreted {
    use std::rc::Rc;
    let mut ctm = DMat4::IDENTITY;
    let (mut material, mut area_light): (Option<Rc<Directive>>, Option<Rc<Directive>>) = (None, None);
    let mut stack = Vec::new();
    let mut shapes = Vec::new();
    let (mut camera, mut film, mut world_from_camera) = (None, None, None);
    let mut in_world = false;
    let mut world = Vec::new();
    let mut others = Vec::new();
    for d in directives(text) {
        match d.name.as_str() {
            "Scale" => {
                let s = d.numbers();
                ctm *= DMat4::from_scale(DVec3::new(s[0], s[1], s[2]));
            }
            "LookAt" => {
                let v = d.numbers();
                ctm *= look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                );
            }
            "Translate" => {
                let v = d.numbers();
                ctm *= DMat4::from_translation(DVec3::new(v[0], v[1], v[2]));
            }
            // pbrt-v4 transposes the 16 values it reads: they are the matrix's columns.
            "Transform" => ctm = DMat4::from_cols_slice(&d.numbers()),
            "Camera" => {
                world_from_camera = Some(ctm.inverse());
                camera = Some(d);
            }
            "Film" => film = Some(d),
            "WorldBegin" => {
                in_world = true;
                ctm = DMat4::IDENTITY;
            }
            "AttributeBegin" => stack.push((ctm, material.clone(), area_light.clone())),
            "AttributeEnd" => (ctm, material, area_light) = stack.pop().expect("balanced attributes"),
            "Material" if in_world => material = Some(Rc::new(d)),
            "AreaLightSource" if in_world => area_light = Some(Rc::new(d)),
            "Shape" if in_world => shapes.push(Bound {
                shape: d,
                transform: ctm,
                material: material.clone(),
                area_light: area_light.clone(),
            }),
            _ if in_world => world.push(d),
            _ => others.push(d),
        }
    }
    assert!(stack.is_empty(), "every AttributeBegin ends");
    Interpreted {
        world_from_camera: world_from_camera.expect("a camera"),
        camera: camera.unwrap(),
        film: film.expect("a film"),
        shapes,
        world,
        others,
    }
}

impl Interpreted {
    /// pbrt's camera ray through raster position (px, py): NDC from the screen window, y down.
    fn ray(&self, px: f64, py: f64) -> (DVec3, DVec3) {
        let w: f64 = self.film.word("integer xresolution").parse().unwrap();
        let h: f64 = self.film.word("integer yresolution").parse().unwrap();
        let sw = self.camera.floats("float screenwindow");
        let sx = sw[0] + px / w * (sw[1] - sw[0]);
        let sy = sw[3] - py / h * (sw[3] - sw[2]);
        let m = self.world_from_camera;
        match self.camera.kind() {
            "perspective" => {
                let t = (self.camera.floats("float fov")[0].to_radians() * 0.5).tan();
                let d = m * DVec4::new(sx * t, sy * t, 1.0, 0.0);
                (m.transform_point3(DVec3::ZERO), d.truncate().normalize())
            }
            "orthographic" => (
                m.transform_point3(DVec3::new(sx, sy, 0.0)),
                (m * DVec4::new(0.0, 0.0, 1.0, 0.0)).truncate().normalize(),
            ),
            other => panic!("camera {other}"),
        }
    }

    fn shapes(&self, kind: &str) -> Vec<&Bound> {
        self.shapes.iter().filter(|b| b.shape.kind() == kind).collect()
    }

    fn other(&self, name: &str) -> &Directive {
        self.others
            .iter()
            .find(|d| d.name == name)
            .unwrap_or_else(|| panic!("no {name}"))
    }
}

fn export(scene: &Path, camera: &str, size: &str, out: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_export"))
        .args([
            scene.to_str().unwrap(),
            "--camera",
            camera,
            "--size",
            size,
            "--to",
            "pbrt",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn every_pixel_of_the_pbrt_camera_is_penumbras() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::repo("experiments/scenes/sphere.toml");
    let scene = Scene::load(&path).unwrap();
    // Both projections, and a portrait image (pbrt's fov would otherwise span its width).
    for (camera, w, h) in [("picture", 64u32, 48u32), ("picture", 30, 70), ("measure", 40, 24)] {
        let out = dir.path().join(format!("{camera}-{w}x{h}"));
        export(&path, camera, &format!("{w}x{h}"), &out);
        let file = interpret(&std::fs::read_to_string(out.join("scene.pbrt")).unwrap());
        let cam = &scene.cameras[camera];
        for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1), (w / 3, h / 2)] {
            let mine = cam.ray(x, y, w, h);
            let (origin, direction) = file.ray(x as f64 + 0.5, y as f64 + 0.5);
            assert!(
                (origin - mine.origin).length() < 1e-12 && (direction - mine.direction).length() < 1e-12,
                "{camera} {w}x{h} pixel ({x}, {y}): pbrt {origin} {direction}, penumbra {} {}",
                mine.origin,
                mine.direction
            );
        }
        assert_eq!(file.film.word("bool savefp16"), "false", "float32 EXR");
        let filter = file.other("PixelFilter");
        assert_eq!(filter.kind(), "box");
        assert_eq!(
            (filter.floats("float xradius"), filter.floats("float yradius")),
            (vec![0.5], vec![0.5])
        );
        let integrator = file.other("Integrator");
        assert_eq!(integrator.kind(), "simplepath");
        assert_eq!(integrator.word("integer maxdepth"), "1", "direct lighting only");
        assert_eq!(integrator.word("bool samplelights"), "true");
    }
}

#[test]
fn the_pbrt_lights_and_surfaces_are_penumbras() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::repo("experiments/scenes/sphere-two-lights.toml");
    let scene = Scene::load(&path).unwrap();
    let out = dir.path().join("two");
    export(&path, "picture", "32x24", &out);
    let file = interpret(&std::fs::read_to_string(out.join("scene.pbrt")).unwrap());
    let disks = file.shapes("disk");
    let lights: Vec<_> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Disk(d) => d,
            Light::Point { .. } => panic!("the scene's lights are disks"),
        })
        .collect();
    assert_eq!(disks.len(), lights.len());
    for (light, disk) in lights.iter().zip(&disks) {
        let m = disk.transform;
        let r = disk.shape.floats("float radius")[0];
        assert_eq!(r, light.radius);
        assert!(
            (m.transform_point3(DVec3::ZERO) - light.center).length() < 1e-15,
            "centre"
        );
        // pbrt's disk normal is +z in object space, flipped when the transform swaps handedness.
        let n = m.transform_vector3(DVec3::Z);
        assert!(m.determinant() > 0.0, "a proper rotation: pbrt flips no normal");
        assert!((n - light.normal).length() < 1e-12, "normal {n} vs {}", light.normal);
        // Radius preserved: the in-plane axes are unit length.
        for axis in [DVec3::X, DVec3::Y] {
            assert!((m.transform_vector3(axis).length() - 1.0).abs() < 1e-12);
        }
        let emitter = disk.area_light.as_ref().expect("the disk emits");
        assert_eq!(emitter.kind(), "diffuse");
        let l = emitter.floats("rgb L");
        let expected = light.power / (std::f64::consts::PI.powi(2) * r * r);
        assert!(
            l.iter().all(|&v| (v / expected - 1.0).abs() < 1e-12),
            "{l:?} vs {expected}"
        );
        // pbrt-v4 divides an RGB emitter by its illuminant's luminance and nothing else unless
        // told: no scale, power, two-sidedness or image may change what `L` says.
        for key in ["float scale", "float power", "bool twosided", "string filename"] {
            assert!(!emitter.params.iter().any(|(k, _)| k == key), "{key} on the light");
        }
    }
    // Nothing else on the film or camera rescales the pixels: sensor, ISO, white balance,
    // clamping and exposure time keep pbrt's neutral defaults.
    for key in [
        "string sensor",
        "float iso",
        "float whitebalance",
        "float maxcomponentvalue",
    ] {
        assert!(!file.film.params.iter().any(|(k, _)| k == key), "{key} on the film");
    }
    for key in ["float shutteropen", "float shutterclose"] {
        assert!(!file.camera.params.iter().any(|(k, _)| k == key), "{key} on the camera");
    }
    let sphere = &file.shapes("sphere")[0];
    assert_eq!(sphere.shape.floats("float radius"), vec![0.25]);
    assert_eq!(
        sphere.transform.transform_point3(DVec3::ZERO),
        DVec3::new(0.0, 0.0, 0.5)
    );
    let plane = &file.shapes("trianglemesh")[0];
    let p = plane.shape.floats("point3 P");
    let corners: Vec<DVec3> = p.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
    assert_eq!(
        plane.shape.floats("integer indices"),
        vec![0.0, 1.0, 2.0, 0.0, 2.0, 3.0]
    );
    assert!(corners.iter().all(|c| c.z == 0.0), "on the ground plane");
    let half = corners
        .iter()
        .map(|c| c.x.abs().min(c.y.abs()))
        .fold(f64::INFINITY, f64::min);
    assert!(half > 2.0, "reaches past the view: {half}");
    for surface in [sphere, plane] {
        let material = surface.material.as_ref().expect("a material of its own");
        assert_eq!(material.kind(), "diffuse");
        assert_eq!(material.floats("rgb reflectance"), vec![0.8; 3]);
        assert!(surface.area_light.is_none(), "surfaces emit nothing");
    }
}

#[test]
fn a_point_light_goes_to_pbrt_with_its_intensity() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap();
    let start = base.find("[[lights]]").unwrap();
    let point = format!(
        "{}[[lights]]\ntype = \"point\"\nposition = [0.1, -0.2, 2.0]\npower = 60.0\n",
        &base[..start]
    );
    let path = dir.path().join("point.toml");
    std::fs::write(&path, point).unwrap();
    let out = dir.path().join("point");
    export(&path, "picture", "16x12", &out);
    let file = interpret(&std::fs::read_to_string(out.join("scene.pbrt")).unwrap());
    let light = file.world.iter().find(|d| d.name == "LightSource").unwrap();
    assert_eq!(light.kind(), "point");
    assert_eq!(light.floats("point3 from"), vec![0.1, -0.2, 2.0]);
    let i = 60.0 / (4.0 * std::f64::consts::PI);
    assert!(light.floats("rgb I").iter().all(|&v| (v / i - 1.0).abs() < 1e-12));
    assert!(file.shapes("disk").is_empty());
}

#[test]
fn a_mesh_goes_to_pbrt_as_the_ply_it_names() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::repo("experiments/scenes/body.toml");
    let scene = Scene::load(&path).unwrap();
    let out = dir.path().join("body");
    export(&path, "picture", "16x16", &out);
    let file = interpret(&std::fs::read_to_string(out.join("scene.pbrt")).unwrap());
    let mesh = &file.shapes("plymesh")[0];
    let ply = std::fs::read(out.join(mesh.shape.word("string filename"))).unwrap();
    let end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&ply[..end]).unwrap();
    let faces = format!("element face {}\n", scene.triangles.positions.len());
    assert!(header.contains(&faces), "{faces} in {header}");
    let vertex = |k: usize| f32::from_le_bytes(ply[end + 4 * k..end + 4 * k + 4].try_into().unwrap()) as f64;
    let first = scene.triangles.positions[0][0];
    assert_eq!(
        DVec3::new(vertex(0), vertex(1), vertex(2)),
        first.as_vec3().as_dvec3(),
        "world-space vertices in f32"
    );
    assert_eq!(mesh.transform, DMat4::IDENTITY, "no transform on top");
    let Shape::Mesh(m) = scene.shapes.iter().find(|s| matches!(s, Shape::Mesh(_))).unwrap() else {
        unreachable!()
    };
    let material = mesh.material.as_ref().expect("the mesh's material");
    assert_eq!(material.floats("rgb reflectance"), vec![m.albedo; 3]);
}
