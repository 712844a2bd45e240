//! Independent reference evaluator ("oracle") for `prespline sample`.
//!
//! This module is shared by the CPU test binary's modules (`tests/cpu`). It is written from
//! the contract in `docs/scene-format.md` only and deliberately uses algorithms different
//! from the product's B-spline-Hermite matrices:
//!
//! * Bézier curves: derivative control points (hodographs) evaluated by de Casteljau.
//! * B-splines: local derivative control points (NURBS Book eq. 3.8 / A3.3 `CurveDerivCpts`)
//!   evaluated by the de Boor triangle (A2 style) on the span containing the parameter.
//! * Rational objects: homogeneous coordinates, projection by the quotient rule
//!   (NURBS Book A4.2 `RatCurveDerivs` / A4.4 `RatSurfaceDerivs`).
//! * Tensor-product surfaces: "curves of curves" (evaluate the u-direction curve of each
//!   control-point column, then the v-direction curve through the results).
//! * ERBS: full Leibniz rule over the blend of two local curves / four local patches.
//! * Expo-rational B-function: graded composite Gauss–Legendre quadrature for B, Taylor
//!   arithmetic (series exponential) for the derivatives.
//!
//! * Hierarchical ERBS ([`erbs_tree`]: constructed, nested, closed, refined): locals reached
//!   through affine maps from the parent's parameter, never split; Hermite locals from the polar
//!   form of the Taylor polynomial.
//! * Structural edits (knot insertion, degree elevation): blossoms (polar forms) evaluated by a
//!   de Boor triangle with one argument per level, not Böhm's insertion or Bézier decomposition.
//!
//! Submodules: [`bfunction`] (the five B-functions), [`eval`] (point evaluation), [`blossom`]
//! (refinement by polar forms), [`scene`]
//! (scene/edit JSON, model, `sample` output), [`compare`] (product vs oracle, error measure),
//! [`condition`] (condition scales for refined control nets),
//! [`random`] + [`rng`] (seeded scenes and edit lists). `gen_expo_table.py` regenerates
//! `tests/data/expo_bfunction_reference.json` with mpmath; the tests themselves need no Python.
//!
//! Running (shared target dir and the global build lock on the development machine):
//! ```text
//! cargo test --test cpu oracle_selfcheck # the oracle against lecture numbers, mpmath, FD, …
//! cargo test --test cpu oracle_agreement # `prespline sample` against the oracle
//! PRESPLINE_ORACLE_SEED=1000007 cargo test --test cpu oracle_agreement::curves   # one seed
//! ```
#![allow(dead_code)]

pub mod bfunction;
pub mod blossom;
pub mod compare;
pub mod condition;
pub mod erbs_tree;
pub mod eval;
pub mod random;
pub mod rng;
pub mod scene;
pub mod trim_area;
