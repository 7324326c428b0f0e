//! # trocar-check — a compiled generated module against the numeric runtime, in a user's tests
//!
//! A module generated with checks (`trocar_codegen::Builder::checks`, or `checks` in
//! `#[constrained_robot(...)]`) holds a type `Checks` that implements [`GeneratedModule`]: every
//! function of the catalogue the module has ([`trocar_model::catalogue::Function`]), evaluated
//! as compiled, in the module's own `f32` or `f64`. A test then reads
//!
//! ```ignore
//! #[test]
//! fn generated_matches_numeric() {
//!     trocar_check::assert_matches_numeric::<arm::Checks>("robots/arm.toml", 2_000);
//! }
//! ```
//!
//! which compares every function with the numeric runtime ([`trocar_model::reference`]: the typed kernels of
//! `trocar` on the description) and the Jacobians with central differences of the module's own
//! poses, at random configurations and parameter values ([`verify::verify`]), and panics with
//! the function, the worst configuration and parameters, the entries that differ and the
//! tolerance ([`verify::Tolerances::F64`], [`verify::Tolerances::F32`]). It also refuses a stale
//! module: one generated from a description file whose bytes have changed since
//! ([`description_hash`]).
//!
//! For properties of one's own (the trocar's lateral velocity is zero for every column of `J^r`,
//! a control step keeps the drift below a bound), [`configurations`] is a proptest strategy over
//! the description's joint and parameter ranges ([`Ranges`]; feature `proptest`, on by default).
//!
//! The crate depends on the core `trocar`, the description reader `trocar-model` and nalgebra
//! (and proptest): no plotting, command-line or file-format crate beyond the model's.
#![warn(missing_docs)]

pub mod verify;

pub use nalgebra::DMatrix;
#[cfg(feature = "proptest")]
pub use proptest;
pub use trocar_model::catalogue::{Function, Fused};
pub use trocar_model::description::RobotDescription;
pub use verify::{Candidate, Check, FusedList, FusedValues, Report, Tolerances};

use std::fmt;
use std::path::Path;
use trocar_model::description::JointKind;
use trocar_model::numeric::RobotError;
use trocar_model::Description;

/// The scalar type a generated module computes in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    /// `f32` (inputs are rounded to `f32`; checked with [`Tolerances::F32`]).
    F32,
    /// `f64` (a generic module is checked in `f64`; [`Tolerances::F64`]).
    F64,
}

impl Scalar {
    /// The tolerances a module in this scalar type is held to.
    pub const fn tolerances(self) -> Tolerances {
        match self {
            Scalar::F32 => Tolerances::F32,
            Scalar::F64 => Tolerances::F64,
        }
    }
}

/// A compiled generated module, as `Builder::checks` emits it (`<module>::Checks`): the
/// [`Candidate`] that evaluates the module's own functions, and what the module was generated
/// from.
pub trait GeneratedModule: Candidate + Default {
    /// The robot's name (`[robot] name`).
    const ROBOT: &'static str;
    /// The scalar type the module computes in.
    const SCALAR: Scalar;
    /// [`description_hash`] of the description file(s) the module was generated from; `None` for
    /// a description given in memory (a preset, an inline attribute).
    const DESCRIPTION_HASH: Option<u64>;
    /// The generator that wrote the module, e.g. `trocar-codegen 0.1.0`.
    const GENERATOR: &'static str;
}

/// FNV-1a (64 bits) of `bytes`, continuing from `state` (start from [`FNV_OFFSET`]); a `const
/// fn`, so that generated modules can compare a description's bytes at build time.
pub const fn fnv1a(mut state: u64, bytes: &[u8]) -> u64 {
    let mut k = 0;
    while k < bytes.len() {
        state ^= bytes[k] as u64;
        state = state.wrapping_mul(0x0000_0100_0000_01b3);
        k += 1;
    }
    state
}

/// The initial state of [`fnv1a`].
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// The hash a generated module records of its description: [`fnv1a`] over the bytes of the
/// description file and then of the URDF its chain comes from, if any
/// ([`RobotDescription::files_read`]).
pub fn description_hash(path: impl AsRef<Path>) -> std::io::Result<u64> {
    let mut state = FNV_OFFSET;
    for file in RobotDescription::files_read(path) {
        state = fnv1a(state, &std::fs::read(file)?);
    }
    Ok(state)
}

/// Why a module could not be checked.
#[derive(Debug)]
pub enum CheckError {
    /// The description could not be read.
    Description(String),
    /// The description is a closed mechanism; the checks cover serial robots.
    Mechanism(String),
    /// The module was generated from another version of the description file.
    Stale {
        /// The description file.
        path: String,
        /// The hash the module records.
        module: u64,
        /// The hash of the file now.
        file: u64,
    },
    /// The module is another robot's.
    WrongRobot {
        /// The robot of the module.
        module: String,
        /// The robot of the description.
        description: String,
    },
    /// The numeric runtime refused the description or a sample.
    Numeric(RobotError),
}

impl fmt::Display for CheckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CheckError::Description(e) => write!(f, "{e}"),
            CheckError::Mechanism(name) => write!(
                f,
                "`{name}` is a closed mechanism: the checks cover serial robots' modules"
            ),
            CheckError::Stale { path, module, file } => write!(
                f,
                "stale module: {path} has changed since the module was generated (description \
                 hash {file:#018x}, the module's {module:#018x}); regenerate the module"
            ),
            CheckError::WrongRobot {
                module,
                description,
            } => write!(
                f,
                "the module is robot `{module}`'s, the description robot `{description}`'s"
            ),
            CheckError::Numeric(e) => write!(f, "numeric runtime: {e}"),
        }
    }
}

impl std::error::Error for CheckError {}

/// Loads the serial description at `path` (a file, or a shipped description's name), e.g. for
/// [`configurations`].
pub fn description(path: &str) -> Result<RobotDescription, CheckError> {
    match Description::load(path).map_err(|e| CheckError::Description(e.to_string()))? {
        Description::Serial(d) => Ok(d),
        Description::Mechanism(m) => Err(CheckError::Mechanism(m.name)),
    }
}

/// Checks the module `M` against the description at `path` (a file, relative to the working
/// directory — the package's root under `cargo test` — or a shipped description's name) at
/// `samples` random configurations drawn from `seed`, with the tolerances of the module's scalar
/// type. Errors when the description cannot be read, is another robot's, or has changed since the
/// module was generated ([`GeneratedModule::DESCRIPTION_HASH`]); a mismatch is a [`Report`] that
/// did not pass.
pub fn check<M: GeneratedModule>(
    path: &str,
    samples: usize,
    seed: u64,
) -> Result<Report, CheckError> {
    let description = description(path)?;
    if let (Some(module), true) = (M::DESCRIPTION_HASH, Path::new(path).exists()) {
        let file = description_hash(path).map_err(|e| CheckError::Description(e.to_string()))?;
        if file != module {
            return Err(CheckError::Stale {
                path: path.into(),
                module,
                file,
            });
        }
    }
    if description.name != M::ROBOT {
        return Err(CheckError::WrongRobot {
            module: M::ROBOT.into(),
            description: description.name,
        });
    }
    verify::verify(
        &description,
        &M::default(),
        samples,
        seed,
        M::SCALAR.tolerances(),
        |_| {},
    )
    .map_err(CheckError::Numeric)
}

/// The seed of [`assert_matches_numeric`].
pub const SEED: u64 = 1;

/// Asserts that the compiled module `M` matches the numeric runtime and finite differences at
/// `samples` random configurations ([`check`], seed [`SEED`]). Panics — this is its job, in a
/// test — with the module's generator, the table of largest errors and, for each failed check,
/// the function, the worst configuration and parameters, the entries that differ and the
/// tolerance; or with why the module could not be checked (a stale module, an unreadable
/// description).
pub fn assert_matches_numeric<M: GeneratedModule>(path: &str, samples: usize) {
    match check::<M>(path, samples, SEED) {
        Ok(report) if report.passed() => {}
        Ok(report) => panic!(
            "the generated module of `{}` ({}, {:?}) does not match the numeric runtime \
             (description {path}, seed {SEED}):\n{report}{}",
            M::ROBOT,
            M::GENERATOR,
            M::SCALAR,
            report.failures()
        ),
        Err(e) => panic!(
            "the generated module of `{}` cannot be checked: {e}",
            M::ROBOT
        ),
    }
}

/// Where the checks and [`configurations`] draw joints and parameters from.
#[derive(Clone, Debug, PartialEq)]
pub struct Ranges {
    /// Per joint, base first: its limits `[lower, upper]` when the description has them,
    /// otherwise `[−π, π]` for a revolute joint and `[−0.5, 0.5]` m for a prismatic one.
    pub joints: Vec<[f64; 2]>,
    /// Per named parameter, in declaration order: its name and `[0.8, 1.2] ×` its nominal value
    /// (ordered).
    pub parameters: Vec<(String, [f64; 2])>,
}

impl Ranges {
    /// The ranges of a description.
    pub fn of(description: &RobotDescription) -> Self {
        let joints = description
            .joints
            .iter()
            .map(|j| match (j.limits, &j.kind) {
                (Some(limits), _) => limits,
                (None, JointKind::Prismatic { .. }) => [-0.5, 0.5],
                (None, _) => [-core::f64::consts::PI, core::f64::consts::PI],
            })
            .collect();
        let parameters = description
            .parameters
            .iter()
            .map(|p| {
                let (a, b) = (0.8 * p.value, 1.2 * p.value);
                (p.name.clone(), [a.min(b), a.max(b)])
            })
            .collect();
        Ranges { joints, parameters }
    }

    /// One sample `(q, params)`, uniform in the ranges.
    pub fn sample(&self, rng: &mut verify::SplitMix64) -> (Vec<f64>, Vec<f64>) {
        let q = self
            .joints
            .iter()
            .map(|[lo, hi]| rng.uniform(*lo, *hi))
            .collect();
        let params = self
            .parameters
            .iter()
            .map(|(_, [lo, hi])| rng.uniform(*lo, *hi))
            .collect();
        (q, params)
    }
}

/// One configuration drawn by [`configurations`].
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// Joint values, base first (`N` of them).
    pub q: Vec<f64>,
    /// Parameter values, in declaration order (the fields of the module's `Params`).
    pub params: Vec<f64>,
}

/// A proptest strategy over the description's joint ranges and parameter ranges ([`Ranges`]):
/// `q` and parameter values uniform within them.
#[cfg(feature = "proptest")]
pub fn configurations(
    description: &RobotDescription,
) -> impl proptest::strategy::Strategy<Value = Configuration> {
    use proptest::prelude::*;
    let ranges = Ranges::of(description);
    let interval = |[lo, hi]: [f64; 2]| -> BoxedStrategy<f64> {
        if lo < hi {
            (lo..hi).boxed()
        } else {
            Just(lo).boxed()
        }
    };
    let q: Vec<_> = ranges.joints.iter().copied().map(interval).collect();
    let params: Vec<_> = ranges
        .parameters
        .iter()
        .map(|(_, r)| interval(*r))
        .collect();
    (q, params).prop_map(|(q, params)| Configuration { q, params })
}

/// The column-major result `[[T; ROWS]; COLS]` of a generated function as a matrix (for the
/// emitted `Checks`).
pub fn from_columns<T: Copy + Into<f64>, const ROWS: usize, const COLS: usize>(
    a: &[[T; ROWS]; COLS],
) -> DMatrix<f64> {
    DMatrix::from_fn(ROWS, COLS, |r, c| a[c][r].into())
}

/// The transform `(R, p)` of a generated function (`R` column-major) as its 4 × 4 homogeneous
/// matrix (for the emitted `Checks`).
pub fn from_transform<T: Copy + Into<f64>>(g: &([[T; 3]; 3], [T; 3])) -> DMatrix<f64> {
    let (r, p) = g;
    DMatrix::from_fn(4, 4, |i, j| match (i, j) {
        (3, 3) => 1.0,
        (3, _) => 0.0,
        (_, 3) => p[i].into(),
        _ => r[j][i].into(),
    })
}

/// A scalar result as a 1 × 1 matrix (for the emitted `Checks`).
pub fn from_scalar<T: Into<f64>>(x: T) -> DMatrix<f64> {
    DMatrix::from_element(1, 1, x.into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_is_the_published_function() {
        // FNV-1a 64 test vectors (Fowler, Noll, Vo): "" and "a".
        assert_eq!(fnv1a(FNV_OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(FNV_OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(
            fnv1a(fnv1a(FNV_OFFSET, b"fo"), b"obar"),
            0x8594_4171_f739_67e8
        );
    }

    #[cfg(feature = "proptest")]
    proptest::proptest! {
        /// The strategy draws within the ranges of the shipped Panda (URDF limits, one parameter).
        #[test]
        fn configurations_stay_within_the_ranges(
            c in configurations(&RobotDescription::preset("panda-laparoscope").unwrap())
        ) {
            let d = RobotDescription::preset("panda-laparoscope").unwrap();
            proptest::prop_assert_eq!((c.q.len(), c.params.len()), (7, 1));
            for (q, j) in c.q.iter().zip(&d.joints) {
                let [lo, hi] = j.limits.unwrap();
                proptest::prop_assert!((lo..=hi).contains(q));
            }
            let l_a = d.parameters[0].value;
            proptest::prop_assert!((0.8 * l_a..=1.2 * l_a).contains(&c.params[0]));
        }
    }

    #[test]
    fn ranges_use_limits_where_given_and_order_negative_parameters() {
        let d = RobotDescription::from_toml_str(
            "[robot]\nname = \"r\"\n[parameters]\nl = -0.5\n\
             [[joints]]\nname = \"a\"\ntype = \"revolute\"\nxyz = [0, 0, \"l\"]\nrpy = [0, 0, 0]\naxis = [0, 0, 1]\nlimits = [-1, 2]\n\
             [[joints]]\nname = \"b\"\ntype = \"prismatic\"\nxyz = [0, 0, 0]\nrpy = [0, 0, 0]\naxis = [0, 0, 1]\n\
             [end_effector]\nxyz = [0, 0, 0]\n",
            None,
        )
        .unwrap();
        let r = Ranges::of(&d);
        assert_eq!(r.joints, vec![[-1.0, 2.0], [-0.5, 0.5]]);
        assert_eq!(r.parameters, vec![("l".to_string(), [-0.6, -0.4])]);
        let mut rng = verify::SplitMix64::new(2);
        for _ in 0..100 {
            let (q, p) = r.sample(&mut rng);
            assert!((-1.0..2.0).contains(&q[0]) && (-0.5..0.5).contains(&q[1]));
            assert!((-0.6..-0.4).contains(&p[0]));
        }
    }
}
