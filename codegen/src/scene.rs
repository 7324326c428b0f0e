//! A scene's step kinematics in one module (`trocar generate SCENE`, [`crate::Builder::scene`],
//! the attribute's `scene = "…"`): every arm's closed forms generated as for one robot (one
//! module per distinct description: the arms of `three-ports` share one, the mirror image of
//! `dia10-dual` has its own), and around them what the runtime's scene step
//! (`trocar::control::scene::Scene::step`) takes, fixed at generation time from the scene file:
//!
//! - `ARMS`, the sizes `A`, `NS = A·N` (the QP's rates), `P` couplings, `C = 2P` coupling rows,
//!   `ES = A·R + shared` equality rows, `SCENE_JOINTS` and `JOINT_MAP` (each arm's joints among
//!   the scene's, a shared joint once), `SHARED`;
//! - `ArmKinematics` (the one module's `Kinematics`, or an enum over the modules that forwards
//!   `ConstrainedKinematics` to each), `ArmController`, `Scene`, `Output`;
//! - `kinematics()`, `bases()`, `rcms()` (each arm's port at its start, its base frame),
//!   `q0()`, `couplings()`, `scene()`, and `step(…)`, one call of the scene's step with them;
//! - with an endoscope, `CAMERA_ARM`, `CAMERA_LOOKS_AT` and `camera()`, its camera task at the
//!   start (`trocar::control::scene::Camera`).
//!
//! Everything is `no_std` and allocation-free: the module uses `core` and the runtime's
//! `emitted` surface only.

use crate::emit::c_scene::SceneC;
use crate::emit::Runtime;
use crate::error::Error;
use crate::ir::Real;
use crate::module::{module_tokens, record_c_symbols, spec_for, ModuleOptions};
use crate::naming::module_name;
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use trocar::control::scene::Between;
use trocar_model::description::{DescriptionError, RobotDescription};
use trocar_model::reference;
use trocar_model::scene::SceneDescription;

/// The scene's module as tokens: `pub mod <scene> { … }`.
pub fn generate_scene(
    scene: &SceneDescription,
    options: &ModuleOptions,
) -> Result<TokenStream, Error> {
    // Sequentially: inside a procedural macro (the attribute) the compiler's token API may only
    // be used from the macro's own thread.
    let parts = parts(scene, options, false)?;
    let (items, rest) = (&parts.arms, &parts.rest);
    Ok(crate::emit::wrap_module(
        &parts.name,
        &parts.doc,
        quote!(#(#items)* #rest),
    ))
}

/// The scene's module in pieces: each distinct arm's module, and the rest of the scene's items.
struct Parts {
    name: String,
    doc: String,
    arms: Vec<TokenStream>,
    rest: TokenStream,
    /// With the C ABI: the scene's C object and its arms' headers and symbols.
    c: Option<SceneCParts>,
}

/// A scene's C ABI beyond its module's code.
struct SceneCParts {
    scene: SceneC,
    /// Each distinct arm module's C and C++ headers: `(file name, text)`.
    headers: Vec<(String, String)>,
    /// Every C symbol the scene's library exports, with the module that exports it.
    symbols: std::collections::BTreeMap<String, String>,
}

/// A scene's module with its C ABI ([`crate::Builder::c_api`]): the module's code, and its
/// headers — each arm module's `<arm>.h` and `<arm>.hpp`, and the scene's `<scene>.h` and
/// `<scene>.hpp` ([`crate::emit::c_scene`]) — as `(file name, text)`, and every C symbol it
/// exports.
pub struct SceneCFiles {
    /// The module (`<scene>.rs`).
    pub code: String,
    /// The headers: `(file name, text)`.
    pub headers: Vec<(String, String)>,
    /// Every C symbol the module exports, with the module (the scene's or an arm's) that
    /// exports it: `(symbol, module)`.
    pub symbols: Vec<(String, String)>,
}

/// The scene's module with its C ABI and its headers ([`SceneCFiles`]); `options.c_api` is
/// taken as on.
pub fn generate_scene_c(
    scene: &SceneDescription,
    options: &ModuleOptions,
) -> Result<SceneCFiles, Error> {
    let options = ModuleOptions {
        c_api: true,
        ..options.clone()
    };
    let (code, c) = generate_scene_parts_string(scene, &options)?;
    let c = c.ok_or_else(|| Error::Internal("the scene's C ABI was not emitted".into()))?;
    let mut headers = c.headers;
    headers.push((format!("{}.h", c.scene.name), c.scene.header(options.real)));
    headers.push((
        format!("{}.hpp", c.scene.name),
        c.scene.cpp_header(options.real),
    ));
    Ok(SceneCFiles {
        code,
        headers,
        symbols: c.symbols.into_iter().collect(),
    })
}

/// `threads`: each distinct arm derived on a thread of its own (not inside a procedural macro).
fn parts(scene: &SceneDescription, options: &ModuleOptions, threads: bool) -> Result<Parts, Error> {
    let runtime = match &options.runtime_path {
        None => Runtime::default(),
        Some(p) => Runtime::new(p).ok_or_else(|| Error::BadRuntimePath(p.clone()))?,
    };
    let rt = runtime.tokens();
    let scene_error = |field: &str, message: String| {
        Error::Description(DescriptionError {
            file: scene.source.clone(),
            line: None,
            column: None,
            field: field.into(),
            message,
        })
    };
    // One module per distinct description, named after its robot (`_mirror` for a mirror
    // image), or after its first arm where that name is taken.
    let mut modules: Vec<(String, &RobotDescription)> = Vec::new();
    let mut arm_module = Vec::with_capacity(scene.arms.len());
    for arm in &scene.arms {
        if let Some(k) = modules.iter().position(|(_, d)| **d == arm.robot) {
            arm_module.push(k);
            continue;
        }
        let mut name = module_name(&arm.robot.name);
        if arm.mirror {
            name += "_mirror";
        }
        if modules.iter().any(|(n, _)| *n == name) {
            name = arm.name.clone();
        }
        // Still taken (an arm named like another's robot): numbered.
        let base = name.clone();
        let mut k = 2;
        while modules
            .iter()
            .any(|(n, _)| *n == name || upper_camel(n) == upper_camel(&name))
        {
            name = format!("{base}_{k}");
            k += 1;
        }
        arm_module.push(modules.len());
        modules.push((name, &arm.robot));
    }
    // Every distinct arm derived on a thread of its own (they are independent), then emitted.
    let arm_options = |name: &String| ModuleOptions {
        module_name: Some(name.clone()),
        description_files: Vec::new(),
        evidence: None,
        checks: None,
        ..options.clone()
    };
    let specs = if threads {
        std::thread::scope(|s| {
            let handles: Vec<_> = modules
                .iter()
                .map(|(name, desc)| s.spawn(move || spec_for(desc, &arm_options(name))))
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join().unwrap_or_else(|_| {
                        Err(Error::Internal("an arm's derivation panicked".into()))
                    })
                })
                .collect::<Result<Vec<_>, Error>>()
        })?
    } else {
        modules
            .iter()
            .map(|(name, desc)| spec_for(desc, &arm_options(name)))
            .collect::<Result<Vec<_>, Error>>()?
    };
    let scene_name =
        crate::naming::checked_module_name(&scene.name, options.module_name.as_deref())?;
    // The C ABI: each arm module's headers and symbols (checked distinct), and what the scene's
    // C object is emitted from.
    let mut c_parts = None;
    if options.c_api {
        let mut headers = Vec::new();
        let mut symbols = std::collections::BTreeMap::new();
        for ((name, _), spec) in modules.iter().zip(&specs) {
            crate::module::c_api_names(spec)?;
            headers.push((
                format!("{name}.h"),
                crate::emit::c_api::header(spec, options.real),
            ));
            if let Some(cpp) = crate::emit::cpp_header::header(spec, options.real) {
                headers.push((format!("{name}.hpp"), cpp));
            }
            record_c_symbols(
                &mut symbols,
                crate::emit::c_api::symbols(spec)
                    .into_iter()
                    .map(|s| (s, name.clone())),
            )?;
        }
        let spec = &specs[0];
        let camera = scene.arms.iter().position(|arm| arm.camera.is_some());
        let task_rows = Literal::usize_unsuffixed(scene.arms[0].robot.task_rows());
        let c_scene = SceneC {
            name: scene_name.clone(),
            arm_modules: arm_module.iter().map(|&k| modules[k].0.clone()).collect(),
            config_fields: crate::emit::c_controller::config_fields(spec),
            arm_size: crate::emit::c_controller::size_bound(spec, options.real),
            joints: spec.joints,
            task_rows: quote!(#task_rows),
            couplings: scene
                .couplings
                .iter()
                .map(|c| [c.influence, c.safety, c.gain])
                .collect(),
            weights: [scene.orientation_weight, scene.rate_weight],
            camera,
        };
        record_c_symbols(
            &mut symbols,
            c_scene
                .symbols()
                .into_iter()
                .map(|s| (s, scene_name.clone())),
        )?;
        c_parts = Some(SceneCParts {
            scene: c_scene,
            headers,
            symbols,
        });
    }
    let mut items = Vec::with_capacity(modules.len());
    for ((name, desc), spec) in modules.iter().zip(specs) {
        if spec
            .controller
            .as_ref()
            .and_then(|c| c.offset.as_ref())
            .is_none()
        {
            let k = scene
                .arms
                .iter()
                .position(|a| a.robot == **desc)
                .unwrap_or(0);
            return Err(scene_error(
                &format!("arms[{k}].robot"),
                format!(
                    "`{}`'s constraint frame does not slide along its link with one parameter \
                     (`g_ir = (R_ir, o + l_a d)`): the scene's step needs the controller's \
                     kinematics, which only such a constraint has",
                    scene.arms[k].robot_source
                ),
            ));
        }
        items.push(module_tokens(desc, &arm_options(name), spec)?);
    }
    let first = format_ident!("{}", modules[0].0);
    let (t, generics, args) = match options.real {
        Real::Generic => (
            quote!(T),
            quote!(<T: #rt::emitted::Real + #rt::emitted::nalgebra::RealField>),
            quote!(<T>),
        ),
        Real::F32 => (quote!(f32), quote!(), quote!()),
        Real::F64 => (quote!(f64), quote!(), quote!()),
    };
    let lit = |v: f64| -> TokenStream {
        match options.real {
            Real::Generic => {
                let v = Literal::f64_unsuffixed(v);
                quote!(<T as #rt::emitted::Arith>::lit(#v))
            }
            Real::F32 => {
                let v = Literal::f32_suffixed(v as f32);
                quote!(#v)
            }
            Real::F64 => {
                let v = Literal::f64_suffixed(v);
                quote!(#v)
            }
        }
    };
    let vector = |v: &[f64]| {
        let entries = v.iter().map(|x| lit(*x));
        quote!(#rt::emitted::nalgebra::SVector::from([#(#entries),*]))
    };
    let matrix3 = |m: &trocar::nalgebra::Matrix3<f64>| {
        // Column-major, as nalgebra's `ArrayStorage`.
        let cols = (0..3).map(|c| {
            let e = (0..3).map(|r| lit(m[(r, c)]));
            quote!([#(#e),*])
        });
        quote!(#rt::emitted::nalgebra::Matrix3::from_data(#rt::emitted::nalgebra::ArrayStorage([#(#cols),*])))
    };
    let vector3 = |v: &trocar::nalgebra::Vector3<f64>| {
        let e = v.iter().map(|x| lit(*x));
        quote!(#rt::emitted::nalgebra::Vector3::new(#(#e),*))
    };
    let a = scene.arms.len();
    let p = scene.couplings.len();
    let task_rows = scene.arms[0].robot.task_rows();
    let q_rows = Literal::usize_unsuffixed(task_rows);
    let shared = scene.shared_joints();
    let names = scene.arms.iter().map(|arm| arm.name.as_str());
    let a_lit = Literal::usize_unsuffixed(a);
    let p_lit = Literal::usize_unsuffixed(p);
    let s_lit = Literal::usize_unsuffixed(shared.len());
    let scene_joints = Literal::usize_unsuffixed(scene.scene_joints());
    let map = scene.joint_map().into_iter().map(|row| {
        let row = row.into_iter().map(Literal::usize_unsuffixed);
        quote!([#(#row),*])
    });
    let shared_items = shared.iter().map(|&(a0, j0, a1, j1)| {
        let (a0, j0, a1, j1) = (
            Literal::usize_unsuffixed(a0),
            Literal::usize_unsuffixed(j0),
            Literal::usize_unsuffixed(a1),
            Literal::usize_unsuffixed(j1),
        );
        quote!(#rt::emitted::SharedJoint { arms: (#a0, #a1), joints: (#j0, #j1) })
    });
    // Each arm's kinematics: the module's type, or the enum over the modules.
    let (kin_items, kin_values) = if modules.len() == 1 {
        (
            quote! {
                /// One arm's kinematics: the arms' module's (every arm has the same description).
                pub type ArmKinematics #args = #first::Kinematics #args;
            },
            (0..a)
                .map(|_| quote!(#first::Kinematics::nominal()))
                .collect::<Vec<_>>(),
        )
    } else {
        let variants: Vec<_> = modules
            .iter()
            .map(|(n, _)| format_ident!("{}", upper_camel(n)))
            .collect();
        let mods: Vec<_> = modules
            .iter()
            .map(|(n, _)| format_ident!("{}", n))
            .collect();
        let docs = modules
            .iter()
            .map(|(n, _)| format!(" The kinematics of module [`{n}`]."));
        let ck = quote!(#rt::emitted::ConstrainedKinematics<#t, N, I, R, K, M, #q_rows>);
        let forward = |call: TokenStream| {
            let arms = variants
                .iter()
                .map(|v| quote!(ArmKinematics::#v(k) => k.#call));
            quote!(match self { #(#arms),* })
        };
        let g_0i = forward(quote!(g_0i(q)));
        let g_0e = forward(quote!(g_0e(q)));
        let h = forward(quote!(h()));
        let shaft = forward(quote!(shaft()));
        let task = forward(quote!(task_selection()));
        let evaluate = forward(quote!(evaluate(q, l_a)));
        let solve_task = forward(quote!(solve_task(j, b)));
        let solve_jb0i = forward(quote!(solve_jb0i(j, b)));
        let at_trocar = forward(quote!(evaluate_at_trocar(q, trocar)));
        let na = quote!(#rt::emitted::nalgebra);
        let state = quote!(#rt::emitted::ConstrainedState<#t, I, R, K, M>);
        let kin_items = quote! {
            /// One arm's kinematics: the module of its description, each forwarding
            /// `ConstrainedKinematics` to it (the arms differ in their description).
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub enum ArmKinematics #generics {
                #(#[doc = #docs] #variants(#mods::Kinematics #args)),*
            }

            impl #generics #ck for ArmKinematics #args {
                #[inline]
                fn g_0i(&self, q: &#na::SVector<#t, N>) -> #rt::emitted::Se3<#t> { #g_0i }
                #[inline]
                fn g_0e(&self, q: &#na::SVector<#t, N>) -> ::core::result::Result<#rt::emitted::Se3<#t>, #rt::emitted::ControlError> { #g_0e }
                #[inline]
                fn h(&self) -> #na::SMatrix<#t, R, 6> { #h }
                #[inline]
                fn shaft(&self) -> #rt::emitted::Shaft<#t> { #shaft }
                #[inline]
                fn task_selection(&self) -> #na::SMatrix<#t, #q_rows, 6> { #task }
                #[inline]
                fn evaluate(&self, q: &#na::SVector<#t, N>, l_a: #t) -> ::core::result::Result<#state, #rt::emitted::ControlError> { #evaluate }
                #[inline]
                fn solve_task(&self, j: &#na::SMatrix<#t, #q_rows, M>, b: &#na::SVector<#t, #q_rows>) -> ::core::option::Option<(#na::SVector<#t, M>, #t)> { #solve_task }
                #[inline]
                fn solve_jb0i(&self, j: &#na::SMatrix<#t, 6, I>, b: &#na::SVector<#t, 6>) -> ::core::option::Option<(#na::SVector<#t, I>, #t)> { #solve_jb0i }
                #[inline]
                fn evaluate_at_trocar(&self, q: &#na::SVector<#t, N>, trocar: &#na::Vector3<#t>) -> ::core::result::Result<(#t, #state), #rt::emitted::ControlError> { #at_trocar }
            }
        };
        let values = arm_module
            .iter()
            .map(|&m| {
                let v = &variants[m];
                let md = &mods[m];
                quote!(ArmKinematics::#v(#md::Kinematics::nominal()))
            })
            .collect();
        (kin_items, values)
    };
    // Placements, ports and starts at generation time, from the numeric models.
    let models = scene.numeric_models()?;
    let ports = scene.ports()?;
    let bases = scene.arms.iter().map(|arm| {
        let r = matrix3(&arm.base.rotation);
        let x = vector3(&arm.base.translation);
        quote!(#rt::emitted::Se3 { rotation: #r, translation: #x })
    });
    let rcms = ports.iter().map(|port| {
        let x = vector3(port);
        quote!(#rt::emitted::Rcm { trocar: #x, dv: #rt::emitted::nalgebra::SVector::zeros() })
    });
    let q0 = scene.arms.iter().map(|arm| vector(&arm.q0));
    let couplings = scene.couplings.iter().map(|c| {
        let (a0, a1) = (
            Literal::usize_unsuffixed(c.arms.0),
            Literal::usize_unsuffixed(c.arms.1),
        );
        let between = match c.between {
            Between::Shafts => quote!(#rt::emitted::Between::Shafts),
            Between::Tips => quote!(#rt::emitted::Between::Tips),
        };
        let (influence, safety, gain) = (lit(c.influence), lit(c.safety), lit(c.gain));
        quote! {
            #rt::emitted::Coupling {
                arms: (#a0, #a1),
                between: #between,
                damper: #rt::emitted::Damper { influence: #influence, safety: #safety, gain: #gain },
            }
        }
    });
    let camera = match scene
        .arms
        .iter()
        .enumerate()
        .find_map(|(k, arm)| arm.camera.as_ref().map(|c| (k, c)))
    {
        None => quote!(),
        Some((k, c)) => {
            let tip = reference::forward_kinematics(&models[k], &scene.arms[k].q0)
                .map_err(|e| scene_error(&format!("arms[{k}].q0"), e.to_string()))?;
            let axis = tip.translation - ports[k];
            let depth = c.depth.unwrap_or_else(|| axis.norm());
            if axis.norm() <= 0.0 || !axis.norm().is_finite() {
                return Err(scene_error(
                    &format!("arms[{k}].camera"),
                    "the endoscope's tip is at its port at the start: no view axis".into(),
                ));
            }
            let (port, start_axis, rotation) = (
                vector3(&ports[k]),
                vector3(&axis.normalize()),
                matrix3(&tip.rotation),
            );
            let depth = lit(depth);
            let looks = c.looks_at.iter().map(|i| Literal::usize_unsuffixed(*i));
            let count = Literal::usize_unsuffixed(c.looks_at.len());
            let arm = Literal::usize_unsuffixed(k);
            let tolerance = Literal::f64_suffixed(c.tolerance);
            quote! {
                /// The endoscope's arm (its index in [`ARMS`]).
                pub const CAMERA_ARM: usize = #arm;
                /// The arms whose tips' midpoint the endoscope looks at.
                pub const CAMERA_LOOKS_AT: [usize; #count] = [#(#looks),*];
                /// How far the view axis may be off its point (rad).
                pub const CAMERA_TOLERANCE: f64 = #tolerance;
                /// The endoscope's camera task at the start (its base frame): its port, depth,
                /// view axis and tip orientation there.
                #[must_use]
                pub fn camera #generics () -> #rt::emitted::Camera<#t> {
                    #rt::emitted::Camera {
                        port: #port,
                        depth: #depth,
                        start_axis: #start_axis,
                        start_rotation: #rotation,
                    }
                }
            }
        }
    };
    let (orientation_weight, rate_weight) = (lit(scene.orientation_weight), lit(scene.rate_weight));
    let doc = scene_doc(scene, &modules);
    let c_items = c_parts.as_ref().map(|c| c.scene.items(options.real, rt));
    let kin_values = &kin_values;
    let rest = quote! {
        /// The arms, in the scene's order.
        pub const ARMS: [&str; #a_lit] = [#(#names),*];
        /// The number of arms.
        pub const A: usize = #a_lit;
        /// The joints of one arm.
        pub const N: usize = #first::N;
        /// The constrained link of every arm.
        pub const I: usize = #first::I;
        /// The port rows of one arm.
        pub const R: usize = #first::R;
        /// The columns of one arm's `Λ#`: `k = 6 − r`.
        pub const K: usize = #first::K;
        /// The columns of one arm's `J^r_0e`: `m = 6 − r + n − i`.
        pub const M: usize = #first::M;
        /// The rates of the scene's QP: every arm's joints (`A·N`).
        pub const NS: usize = A * N;
        /// The number of couplings.
        pub const P: usize = #p_lit;
        /// The coupling rows of the scene's QP (two per coupling).
        pub const C: usize = 2 * P;
        /// The joints the arms share (a torso), each pair once.
        pub const SHARED: [#rt::emitted::SharedJoint; #s_lit] = [#(#shared_items),*];
        /// The equality rows of the scene's QP: every arm's port rows and the shared joints.
        pub const ES: usize = A * R + SHARED.len();
        /// The scene's joints (a shared joint once).
        pub const SCENE_JOINTS: usize = #scene_joints;
        /// Each arm's joints among the scene's joints (0-based).
        pub const JOINT_MAP: [[usize; N]; A] = [#(#map),*];

        #kin_items

        /// One arm's controller (every arm's the same sizes).
        pub type ArmController #args = #rt::emitted::Controller<#t, N, I, R, K, M, #q_rows>;
        /// The scene's step: its couplings and its QP's warm start.
        pub type Scene #args = #rt::emitted::Scene<#t, P, NS, C>;
        /// What one scene step commands and measures.
        pub type Output #args = #rt::emitted::SceneOutput<#t, A, N, R, P>;

        /// Each arm's kinematics, at the scene's parameters.
        #[must_use]
        pub fn kinematics #generics () -> [ArmKinematics #args; A] {
            [#(#kin_values),*]
        }

        /// Each arm's base in the scene's frame.
        #[must_use]
        pub fn bases #generics () -> [#rt::emitted::Se3<#t>; A] {
            [#(#bases),*]
        }

        /// Each arm's port (its constraint frame's origin at the start, its base frame), held
        /// still.
        #[must_use]
        pub fn rcms #generics () -> [#rt::emitted::Rcm<#t, R>; A] {
            [#(#rcms),*]
        }

        /// Each arm's joints at the start.
        #[must_use]
        pub fn q0 #generics () -> [#rt::emitted::nalgebra::SVector<#t, N>; A] {
            [#(#q0),*]
        }

        /// The couplings: which arms, shafts or tips, and their dampers.
        #[must_use]
        pub fn couplings #generics () -> [#rt::emitted::Coupling<#t>; P] {
            [#(#couplings),*]
        }

        /// The scene's step with its couplings and its weights.
        #[must_use]
        pub fn scene #generics () -> Scene #args {
            let mut scene = #rt::emitted::Scene::new(couplings());
            scene.orientation_weight = #orientation_weight;
            scene.rate_weight = #rate_weight;
            scene
        }

        /// One step of the scene: each arm's own step toward its reference, then the couplings
        /// and the shared joints (`Scene::step` with [`rcms`], [`bases`] and [`SHARED`]).
        ///
        /// # Errors
        /// As `Scene::step`: an arm's step failed, or a non-finite value appeared.
        pub fn step #generics (
            scene: &mut Scene #args,
            arms: &mut [ArmController #args; A],
            kins: &[ArmKinematics #args; A],
            q: &[#rt::emitted::nalgebra::SVector<#t, N>; A],
            references: &[#rt::emitted::Reference<#t>; A],
            dt: #t,
        ) -> ::core::result::Result<Output #args, #rt::emitted::SceneError> {
            scene.step::<ArmKinematics #args, A, N, I, R, K, M, #q_rows, ES>(
                arms,
                kins,
                q,
                references,
                &rcms(),
                &bases(),
                &SHARED,
                dt,
            )
        }

        #camera
        #c_items
    };
    Ok(Parts {
        name: scene_name,
        doc,
        arms: items,
        rest,
        c: c_parts,
    })
}

/// [`generate_scene`] as a formatted file (prettyplease, headed by the `@generated` line).
///
/// Not for a procedural macro (it uses threads; the attribute takes [`generate_scene`]). With
/// several arm modules, each is derived and formatted on a thread of its own and set into the
/// formatted scene module, indented one level (formatting, mostly parsing the tokens again, is most of a
/// module's generation; the arms' modules are independent).
pub fn generate_scene_string(
    scene: &SceneDescription,
    options: &ModuleOptions,
) -> Result<String, Error> {
    generate_scene_parts_string(scene, options).map(|(code, _)| code)
}

/// [`generate_scene_string`], with the scene's C ABI beyond its code where it has one.
fn generate_scene_parts_string(
    scene: &SceneDescription,
    options: &ModuleOptions,
) -> Result<(String, Option<SceneCParts>), Error> {
    const MARK: &str = "const TROCAR_ARM_MODULES: () = ();";
    let parts = parts(scene, options, true)?;
    if parts.arms.len() == 1 {
        // One arm module: formatted whole (no thread to share it with).
        let (items, rest) = (&parts.arms, &parts.rest);
        let code = crate::emit::format_file(crate::emit::wrap_module(
            &parts.name,
            &parts.doc,
            quote!(#(#items)* #rest),
        ))
        .map_err(|e| Error::Internal(e.to_string()))?;
        return Ok((code, parts.c));
    }
    let mark: TokenStream = MARK.parse().map_err(|e| Error::Internal(format!("{e}")))?;
    let rest = &parts.rest;
    let skeleton = crate::emit::format_file(crate::emit::wrap_module(
        &parts.name,
        &parts.doc,
        quote!(#mark #rest),
    ))
    .map_err(|e| Error::Internal(e.to_string()))?;
    // Token streams are not `Send`: their text is.
    let texts: Vec<String> = parts.arms.iter().map(ToString::to_string).collect();
    let arms = std::thread::scope(|s| {
        let handles: Vec<_> = texts
            .iter()
            .map(|t| {
                s.spawn(move || {
                    syn::parse_str::<syn::File>(t)
                        .map(|f| prettyplease::unparse(&f))
                        .map_err(|e| e.to_string())
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("an arm's formatting panicked".into()))
                    .map_err(Error::Internal)
            })
            .collect::<Result<Vec<_>, Error>>()
    })?;
    let mut out =
        String::with_capacity(skeleton.len() + arms.iter().map(String::len).sum::<usize>());
    let mut placed = false;
    for line in skeleton.lines() {
        if line.trim() == MARK {
            let indent = &line[..line.len() - line.trim_start().len()];
            for (k, arm) in arms.iter().enumerate() {
                if k > 0 {
                    out.push('\n');
                }
                for l in arm.lines() {
                    if !l.is_empty() {
                        out.push_str(indent);
                        out.push_str(l);
                    }
                    out.push('\n');
                }
            }
            placed = true;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    if !placed {
        return Err(Error::Internal(
            "the scene module's place for its arms was not found".into(),
        ));
    }
    Ok((out, parts.c))
}

/// `three_ports` → `ThreePorts`.
fn upper_camel(name: &str) -> String {
    name.split('_')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let mut c = s.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect()
}

fn scene_doc(scene: &SceneDescription, modules: &[(String, &RobotDescription)]) -> String {
    let plural =
        |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    let mut doc = format!(
        "The scene `{}`: {}, each through its own port (the thesis's §5.2), {}.\n\n",
        scene.name,
        plural(scene.arms.len(), "arm", "arms"),
        plural(scene.couplings.len(), "coupling", "couplings")
    );
    for (k, arm) in scene.arms.iter().enumerate() {
        let module = modules
            .iter()
            .find(|(_, d)| **d == arm.robot)
            .map_or("", |(n, _)| n.as_str());
        doc += &format!(
            "- arm {k} `{}`: `{}`{} (module [`{module}`]){}\n",
            arm.name,
            arm.robot_source,
            if arm.mirror { ", mirrored" } else { "" },
            match arm.shares {
                Some((other, count)) => format!(
                    ", its first {} shared with `{}`",
                    plural(count, "joint", "joints"),
                    scene.arms[other].name
                ),
                None => String::new(),
            }
        );
    }
    for c in &scene.couplings {
        doc += &format!(
            "- coupling `{}`–`{}` between their {}: safety {} m, influence {} m\n",
            scene.arms[c.arms.0].name,
            scene.arms[c.arms.1].name,
            match c.between {
                Between::Shafts => "shafts",
                Between::Tips => "tips",
            },
            c.safety,
            c.influence
        );
    }
    doc += "\nThe step: [`step`] with [`scene`], [`kinematics`], one [`ArmController`] per arm \
            and each arm's reference; the arms' constants and closed forms are in their modules.";
    doc
}
