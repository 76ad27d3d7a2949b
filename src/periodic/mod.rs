//! Periodic maps: the transforms that carry a surface onto its periodic partner.
//!
//! A periodic condition is an interaction between a destination surface and the *image*
//! of a source surface under a map; the image is made before search and then paired
//! like any other surface. Entry points: [`PeriodicMap`] (the trait), [`Translation`]
//! (`Rectangular Offset`), [`Rotation`] (`Cylindrical Axis Center Angle`),
//! [`Rigid`] (`Align_Surface`, built by [`align_surface`]) and [`LuaMap`] (`Mapped`).
//!
//! Conventions: angles in the deck are degrees, counter-clockwise about the axis by the
//! right-hand rule; vectors (normals) are mapped by the map's linear part — for a Lua
//! map, by its Jacobian, formed by central differences.

use std::path::{Component, Path, PathBuf};

use crate::script::{Limits, Sandbox, ScriptError, ScriptFn};
use crate::vec3::{cross, dot, norm, normalize as unit, sub};

pub type Vec3 = [f64; 3];

/// A map of points (and of directions at a point) from a source surface to its image.
pub trait PeriodicMap {
    fn map_point(&mut self, p: Vec3) -> Result<Vec3, ScriptError>;
    /// Map a direction attached to `at` (a normal, a tangent); not normalised.
    fn map_vector(&mut self, at: Vec3, v: Vec3) -> Result<Vec3, ScriptError>;
}

/// `Rectangular Offset = dx dy [dz]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Translation(pub Vec3);

impl PeriodicMap for Translation {
    fn map_point(&mut self, p: Vec3) -> Result<Vec3, ScriptError> {
        Ok([p[0] + self.0[0], p[1] + self.0[1], p[2] + self.0[2]])
    }
    fn map_vector(&mut self, _: Vec3, v: Vec3) -> Result<Vec3, ScriptError> {
        Ok(v)
    }
}

/// A rigid map `x ↦ R (x − c) + c + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid {
    pub rotation: [[f64; 3]; 3],
    pub center: Vec3,
    pub translation: Vec3,
}

impl PeriodicMap for Rigid {
    fn map_point(&mut self, p: Vec3) -> Result<Vec3, ScriptError> {
        let d = sub(p, self.center);
        let r = mat_vec(&self.rotation, d);
        Ok([
            r[0] + self.center[0] + self.translation[0],
            r[1] + self.center[1] + self.translation[1],
            r[2] + self.center[2] + self.translation[2],
        ])
    }
    fn map_vector(&mut self, _: Vec3, v: Vec3) -> Result<Vec3, ScriptError> {
        Ok(mat_vec(&self.rotation, v))
    }
}

/// `Cylindrical Axis = a Center = c Angle = θ` as a [`Rigid`] map.
pub struct Rotation;

impl Rotation {
    /// Rotation by `angle_deg` about the line through `center` along `axis` (2-D decks
    /// give no z: the axis is then z). `None` if the axis is the zero vector.
    pub fn about(axis: Vec3, center: Vec3, angle_deg: f64) -> Option<Rigid> {
        let n = norm(axis);
        if n == 0.0 || !n.is_finite() {
            return None;
        }
        let k = [axis[0] / n, axis[1] / n, axis[2] / n];
        Some(Rigid {
            rotation: rodrigues(k, angle_deg.to_radians()),
            center,
            translation: [0.0; 3],
        })
    }
}

/// Rodrigues' formula: R = I + sin θ K + (1 − cos θ) K², K the cross-product matrix of
/// the unit axis k.
fn rodrigues(k: Vec3, theta: f64) -> [[f64; 3]; 3] {
    let (s, c) = theta.sin_cos();
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let k2: f64 = (0..3).map(|m| kx[i][m] * kx[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + s * kx[i][j] + (1.0 - c) * k2;
        }
    }
    r
}

/// `Align_Surface Destination = D [Invert_Normals = 0|1]`: the rigid map that takes the
/// source's centroid onto the destination's and turns the source's mean normal onto the
/// destination's — reversed when `invert_normals` (the default: the image then faces
/// the destination, as two sides of an interface do). The turn is the smallest rotation
/// doing so; an exact half turn picks an axis perpendicular to the source normal.
pub fn align_surface(
    source_centroid: Vec3,
    source_normal: Vec3,
    dest_centroid: Vec3,
    dest_normal: Vec3,
    invert_normals: bool,
) -> Option<Rigid> {
    let a = unit(source_normal)?;
    let mut b = unit(dest_normal)?;
    if invert_normals {
        b = b.map(|x| -x);
    }
    let axis = cross(a, b);
    let s = norm(axis);
    let c = dot(a, b);
    let rotation = if s < 1e-14 {
        if c > 0.0 {
            rodrigues([0.0, 0.0, 1.0], 0.0)
        } else {
            // Half turn about any axis perpendicular to a.
            let trial = if a[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            rodrigues(unit(cross(a, trial))?, std::f64::consts::PI)
        }
    } else {
        rodrigues([axis[0] / s, axis[1] / s, axis[2] / s], s.atan2(c))
    };
    Some(Rigid {
        rotation,
        center: source_centroid,
        translation: sub(dest_centroid, source_centroid),
    })
}

/// Where a `Mapped` component comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MapSource {
    /// A Lua expression in `x`, `y`, `z`.
    Expression(String),
    /// A function of `(x, y, z)` defined in a Lua file (path relative to the deck).
    Function { file: PathBuf, name: String },
}

impl MapSource {
    /// Read a deck value: `file.lua:function` names a function in a file, anything else
    /// is an expression.
    pub fn parse(text: &str) -> MapSource {
        let t = text.trim();
        if let Some((file, name)) = t.rsplit_once(':')
            && file.ends_with(".lua")
            && !name.is_empty()
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        {
            return MapSource::Function {
                file: PathBuf::from(file),
                name: name.to_string(),
            };
        }
        MapSource::Expression(t.to_string())
    }
}

/// Why a Lua map could not be set up.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MapError {
    #[error("Lua file {0} is outside the deck's directory")]
    OutsideDeck(PathBuf),
    #[error(transparent)]
    Script(#[from] ScriptError),
}

/// `Mapped X_Map = f Y_Map = g [Z_Map = h]`: each component a Lua function of (x, y, z),
/// compiled once; with no `Z_Map`, z is kept.
pub struct LuaMap {
    sandbox: Sandbox,
    components: [Option<ScriptFn>; 3],
    /// Step for the central-difference Jacobian, relative to the model size.
    step: f64,
}

impl LuaMap {
    /// Compile the maps. Files are read relative to `deck_dir` and must stay inside it;
    /// `chunk` names the deck location for messages; `model_size` scales the
    /// finite-difference step used to map vectors.
    pub fn new(
        maps: [Option<&MapSource>; 3],
        deck_dir: &Path,
        chunk: &str,
        model_size: f64,
    ) -> Result<LuaMap, MapError> {
        let sandbox = Sandbox::new(Limits::default())?;
        let mut loaded: Vec<PathBuf> = Vec::new();
        let mut components: [Option<ScriptFn>; 3] = [None, None, None];
        for (slot, map) in components.iter_mut().zip(maps) {
            let Some(map) = map else { continue };
            *slot = Some(match map {
                MapSource::Expression(e) => sandbox.expression(chunk, e, &["x", "y", "z"])?,
                MapSource::Function { file, name } => {
                    let path = inside(deck_dir, file)
                        .ok_or_else(|| MapError::OutsideDeck(file.clone()))?;
                    if !loaded.contains(&path) {
                        sandbox.run_file(&path)?;
                        loaded.push(path.clone());
                    }
                    sandbox.function(name, &path.display().to_string())?
                }
            });
        }
        Ok(LuaMap {
            sandbox,
            components,
            // ~ cube root of machine epsilon: the optimal central-difference step.
            step: 6e-6 * model_size.max(f64::MIN_POSITIVE),
        })
    }
}

impl PeriodicMap for LuaMap {
    fn map_point(&mut self, p: Vec3) -> Result<Vec3, ScriptError> {
        let mut out = p;
        for (d, f) in self.components.iter().enumerate() {
            if let Some(f) = f {
                out[d] = self.sandbox.call(f, &p)?;
            }
        }
        Ok(out)
    }

    fn map_vector(&mut self, at: Vec3, v: Vec3) -> Result<Vec3, ScriptError> {
        // J v ≈ (f(x + h v̂) − f(x − h v̂)) |v| / 2h.
        let len = norm(v);
        if len == 0.0 {
            return Ok(v);
        }
        let h = self.step;
        let fwd = self.map_point(std::array::from_fn(|d| at[d] + h * v[d] / len))?;
        let bwd = self.map_point(std::array::from_fn(|d| at[d] - h * v[d] / len))?;
        Ok(std::array::from_fn(|d| (fwd[d] - bwd[d]) * len / (2.0 * h)))
    }
}

/// `file` resolved under `dir`, refusing absolute paths and `..` that climbs out.
fn inside(dir: &Path, file: &Path) -> Option<PathBuf> {
    let mut depth = 0i32;
    for c in file.components() {
        match c {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return None;
                }
            }
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(dir.join(file))
}

/// Apply a map `n` times to `p` and return the distance from `p`: an N-fold rotation
/// must come back (closure check for cylindrical and mapped rotations).
pub fn closure_error(map: &mut dyn PeriodicMap, p: Vec3, n: usize) -> Result<f64, ScriptError> {
    let mut q = p;
    for _ in 0..n {
        q = map.map_point(q)?;
    }
    Ok(norm(sub(q, p)))
}

/// The N of an angle that divides the full turn (`360/θ` within 1e-9 of an integer).
pub fn fold_count(angle_deg: f64) -> Option<usize> {
    let n = 360.0 / angle_deg.abs();
    let r = n.round();
    (r >= 1.0 && (n - r).abs() < 1e-9 * n).then_some(r as usize)
}

fn mat_vec(m: &[[f64; 3]; 3], v: Vec3) -> Vec3 {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        norm(sub(a, b)) <= tol
    }

    #[test]
    fn rotation_turns_counter_clockwise_about_z() {
        let mut r = Rotation::about([0.0, 0.0, 2.0], [1.0, 0.0, 0.0], 90.0).unwrap();
        assert!(close(
            r.map_point([2.0, 0.0, 5.0]).unwrap(),
            [1.0, 1.0, 5.0],
            1e-15
        ));
        assert!(close(
            r.map_vector([0.0; 3], [1.0, 0.0, 0.0]).unwrap(),
            [0.0, 1.0, 0.0],
            1e-15
        ));
    }

    #[test]
    fn twelve_thirty_degree_turns_close_up() {
        let mut r = Rotation::about([0.0, 0.0, 1.0], [0.0; 3], 30.0).unwrap();
        assert_eq!(fold_count(30.0), Some(12));
        assert_eq!(fold_count(7.0), None);
        let e = closure_error(&mut r, [3.0, 1.0, 2.0], 12).unwrap();
        assert!(e < 1e-12 * 3.0, "closure error {e}");
    }

    #[test]
    fn align_surface_faces_the_destination() {
        // Source: the face x = 0 of a unit cube (outward normal −x, centroid (0, .5, .5));
        // destination: the face y = 3 of another part, outward normal +y.
        let mut m = align_surface(
            [0.0, 0.5, 0.5],
            [-1.0, 0.0, 0.0],
            [2.0, 3.0, 0.5],
            [0.0, 1.0, 0.0],
            true,
        )
        .unwrap();
        assert!(close(
            m.map_point([0.0, 0.5, 0.5]).unwrap(),
            [2.0, 3.0, 0.5],
            1e-15
        ));
        let n = m.map_vector([0.0; 3], [-1.0, 0.0, 0.0]).unwrap();
        assert!(
            close(n, [0.0, -1.0, 0.0], 1e-15),
            "image normal must oppose the destination's: {n:?}"
        );
        // Without inversion the image normal equals the destination's.
        let mut m =
            align_surface([0.0; 3], [-1.0, 0.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0], false).unwrap();
        assert!(close(
            m.map_vector([0.0; 3], [-1.0, 0.0, 0.0]).unwrap(),
            [1.0, 0.0, 0.0],
            1e-15
        ));
    }

    #[test]
    fn lua_map_reproduces_a_rotation() {
        let (s, c) = 30f64.to_radians().sin_cos();
        let x = MapSource::parse(&format!("{c:.17}*x - {s:.17}*y"));
        let y = MapSource::parse(&format!("{s:.17}*x + {c:.17}*y"));
        let mut lua = LuaMap::new([Some(&x), Some(&y), None], Path::new("."), "test", 1.0).unwrap();
        let mut rigid = Rotation::about([0.0, 0.0, 1.0], [0.0; 3], 30.0).unwrap();
        let p = [0.3, -1.2, 0.7];
        assert!(close(
            lua.map_point(p).unwrap(),
            rigid.map_point(p).unwrap(),
            1e-15
        ));
        let v = lua.map_vector(p, [0.0, 1.0, 0.0]).unwrap();
        assert!(
            close(v, rigid.map_vector(p, [0.0, 1.0, 0.0]).unwrap(), 1e-9),
            "{v:?}"
        );
    }

    #[test]
    fn map_sources_and_paths() {
        assert_eq!(
            MapSource::parse("maps/twist.lua:x_of"),
            MapSource::Function {
                file: "maps/twist.lua".into(),
                name: "x_of".into()
            }
        );
        assert_eq!(
            MapSource::parse("x + 1"),
            MapSource::Expression("x + 1".into())
        );
        assert!(inside(Path::new("/d"), Path::new("../etc/x.lua")).is_none());
        assert!(inside(Path::new("/d"), Path::new("/etc/x.lua")).is_none());
        assert!(inside(Path::new("/d"), Path::new("a/../b.lua")).is_some());
    }
}
