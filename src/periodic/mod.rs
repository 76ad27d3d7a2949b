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

use std::f64::consts::PI;
use std::path::{Component, Path, PathBuf};

use nalgebra::{IsometryMatrix3, Point3, Rotation3, Translation3, Unit, Vector3};

use crate::script::{Limits, Sandbox, ScriptError, ScriptFn};
use crate::vec3::{norm, normalize as unit, sub};

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

/// A rigid map `x ↦ R (x − c) + c + t`: a turn `R` about the centre `c`, then a move
/// by `t`; held as the isometry `x ↦ R x + (c − R c + t)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid(IsometryMatrix3<f64>);

impl Rigid {
    /// Turn by `rotation` about `center`, then move by `translation`.
    fn new(rotation: Rotation3<f64>, center: Vec3, translation: Vec3) -> Rigid {
        let turn = IsometryMatrix3::rotation_wrt_point(rotation, Point3::from(center));
        Rigid(Translation3::from(translation) * turn)
    }
}

impl PeriodicMap for Rigid {
    fn map_point(&mut self, p: Vec3) -> Result<Vec3, ScriptError> {
        Ok(self.0.transform_point(&Point3::from(p)).into())
    }
    fn map_vector(&mut self, _: Vec3, v: Vec3) -> Result<Vec3, ScriptError> {
        Ok(self.0.transform_vector(&Vector3::from(v)).into())
    }
}

/// `Cylindrical Axis = a Center = c Angle = θ` as a [`Rigid`] map.
pub struct Rotation;

impl Rotation {
    /// Rotation by `angle_deg` about the line through `center` along `axis` (2-D decks
    /// give no z: the axis is then z). `None` if the axis is the zero vector.
    pub fn about(axis: Vec3, center: Vec3, angle_deg: f64) -> Option<Rigid> {
        let (k, n) = Unit::try_new_and_get(Vector3::from(axis), 0.0)?;
        if !n.is_finite() {
            return None;
        }
        let turn = Rotation3::from_axis_angle(&k, angle_deg.to_radians());
        Some(Rigid::new(turn, center, [0.0; 3]))
    }
}

/// `Align_Surface Destination = D [Invert_Normals = 0|1]`: the rigid map that takes the
/// source's centroid onto the destination's and turns the source's mean normal onto the
/// destination's — reversed when `invert_normals` (the default: the image then faces
/// the destination, as two sides of an interface do). The turn is the smallest rotation
/// doing so; an exact half turn picks an axis perpendicular to the source normal.
///
/// Not nalgebra's `Rotation3::rotation_between`: it takes the angle from `acos(a · b)`,
/// which loses half the digits of a small angle (1e-8 rad comes out as 0), and has no
/// half turn; `atan2(|a × b|, a · b)` is accurate at every angle.
pub fn align_surface(
    source_centroid: Vec3,
    source_normal: Vec3,
    dest_centroid: Vec3,
    dest_normal: Vec3,
    invert_normals: bool,
) -> Option<Rigid> {
    let a = Vector3::from(unit(source_normal)?);
    let mut b = Vector3::from(unit(dest_normal)?);
    if invert_normals {
        b = -b;
    }
    // |a × b| below 1e-14: the normals are parallel to round-off, a turn of 0 or π.
    let turn = match Unit::try_new_and_get(a.cross(&b), 1e-14) {
        Some((axis, s)) => Rotation3::from_axis_angle(&axis, s.atan2(a.dot(&b))),
        None if a.dot(&b) > 0.0 => Rotation3::identity(),
        None => {
            // Half turn about any axis perpendicular to a.
            let trial = if a.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            Rotation3::from_axis_angle(&Unit::new_normalize(a.cross(&trial)), PI)
        }
    };
    Some(Rigid::new(
        turn,
        source_centroid,
        sub(dest_centroid, source_centroid),
    ))
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

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::vec3::{cross, dot};

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

    /// The rotation this module computed before nalgebra, kept as the property tests'
    /// reference: Rodrigues' formula R = I + sin θ K + (1 − cos θ) K², K the
    /// cross-product matrix of the unit axis k.
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

    /// `x ↦ R (x − c) + c + t` with the old matrix `r`, as the old map computed it.
    fn rigid_by_hand(r: &[[f64; 3]; 3], c: Vec3, t: Vec3, p: Vec3) -> Vec3 {
        let d = sub(p, c);
        std::array::from_fn(|i| r[i][0] * d[0] + r[i][1] * d[1] + r[i][2] * d[2] + c[i] + t[i])
    }

    fn coordinate() -> impl Strategy<Value = f64> {
        -1.0..1.0f64
    }

    fn triple() -> impl Strategy<Value = Vec3> {
        prop::array::uniform3(coordinate())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// nalgebra's axis-angle rotation against the Rodrigues formula it replaced, on
        /// random axes, angles (up to two turns either way), centres and points. Each
        /// entry is a sum of a few products of numbers ≤ 1, so the two differ by a few
        /// units of 1e-16; 1e-14 leaves room and still catches a wrong sign or
        /// transposition (which moves entries by O(sin θ)).
        #[test]
        fn rotation_equals_the_rodrigues_formula(
            axis in triple(),
            angle in -720.0..720.0f64,
            center in triple(),
            p in triple(),
        ) {
            let n = norm(axis);
            prop_assume!(n > 1e-3);
            let old = rodrigues(axis.map(|x| x / n), angle.to_radians());
            let mut new = Rotation::about(axis, center, angle).unwrap();
            let m = new.0.rotation.matrix();
            for (i, row) in old.iter().enumerate() {
                for (j, &r) in row.iter().enumerate() {
                    prop_assert!((m[(i, j)] - r).abs() <= 1e-14, "R[{i}][{j}]: {} against {r}", m[(i, j)]);
                }
            }
            let want = rigid_by_hand(&old, center, [0.0; 3], p);
            let got = new.map_point(p).unwrap();
            prop_assert!(close(got, want, 1e-14), "{got:?} against {want:?}");
        }

        /// `Align_Surface` against the old construction (axis a × b, angle
        /// atan2(|a × b|, a · b), by Rodrigues): same rotation, same map, to 1e-14.
        #[test]
        fn align_surface_equals_the_rodrigues_construction(
            na in triple(),
            nb in triple(),
            ca in triple(),
            cb in triple(),
            p in triple(),
            invert in any::<bool>(),
        ) {
            prop_assume!(norm(na) > 1e-3 && norm(nb) > 1e-3);
            let a = unit(na).unwrap();
            let b = unit(nb).unwrap().map(|x| if invert { -x } else { x });
            let axis = cross(a, b);
            let s = norm(axis);
            prop_assume!(s >= 1e-12);
            let old = rodrigues(axis.map(|x| x / s), s.atan2(dot(a, b)));
            let mut new = align_surface(ca, na, cb, nb, invert).unwrap();
            let want = rigid_by_hand(&old, ca, sub(cb, ca), p);
            let got = new.map_point(p).unwrap();
            prop_assert!(close(got, want, 1e-14), "{got:?} against {want:?}");
            let v = new.map_vector(p, na).unwrap();
            let want = rigid_by_hand(&old, [0.0; 3], [0.0; 3], na);
            prop_assert!(close(v, want, 1e-14), "{v:?} against {want:?}");
        }
    }

    #[test]
    fn align_surface_turns_exactly_parallel_normals_by_nothing_or_a_half_turn() {
        let n = [0.3, -0.4, 1.2];
        let mut same = align_surface([0.0; 3], n, [1.0, 2.0, 3.0], n, false).unwrap();
        assert_eq!(same.map_vector([0.0; 3], n).unwrap(), n);
        let mut opposed = align_surface([0.0; 3], n, [0.0; 3], n, true).unwrap();
        let v = opposed.map_vector([0.0; 3], n).unwrap();
        assert!(close(v, n.map(|x| -x), 1e-15), "{v:?}");
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
