//! Walking the shapes: from each root product through its components, every face instance in
//! its place, with its product's name, its colour and its transformation to the root's space
//! in millimetres.
//!
//! Transformations. A component's placement relates two AXIS2_PLACEMENT_3Ds, one in the
//! component's representation and one in the assembly's; the component is placed so that its
//! item coincides with the assembly's: `p_assembly = A_assembly · A_component⁻¹ · p`. ISO 10303
//! says ITEM_DEFINED_TRANSFORMATION maps transform_item_1 (in rep_1) onto transform_item_2 (in
//! rep_2) and the recommended practice has rep_1 = the component; writers that swap rep_1 and
//! rep_2 (AP203 files from several systems) put their items the other way round too, so the
//! rule above, deciding which representation is the component's by the product structure,
//! reads both (OpenCASCADE does the same, see its CheckSRRReversesNAUO). MAPPED_ITEM places its
//! REPRESENTATION_MAP's representation by mapping_origin → mapping_target the same way.
//! Placements are in their representation's length unit, converted to mm here.

use std::collections::{HashMap, HashSet};

use crate::formats::step::{EntityRef, StepFile};
use glam::{DAffine3, DMat3, DVec3};

use super::attrs::{P, Res, bad, direction, frame, is, part, point3};
use super::products::Products;
use super::units;

/// How deeply assemblies, mapped items and shells may nest.
const MAX_DEPTH: usize = 64;

/// One face to draw.
#[derive(Clone, Debug)]
pub(crate) struct Instance {
    /// The ADVANCED_FACE / FACE_SURFACE.
    pub face: u64,
    /// Oriented shells and faces on the way flip it.
    pub flip: bool,
    /// File units of the face's representation → root mm.
    pub to_mm: DAffine3,
    /// Radians per angle unit of the face's representation.
    pub rad: f64,
    pub product: String,
    pub colour: Option<[f64; 3]>,
}

/// The walk's results besides the instances: entity types found among shape items but not
/// drawn, with a count and the first `(line, id)`.
#[derive(Default)]
pub(crate) struct Walk {
    pub instances: Vec<Instance>,
    pub not_drawn: HashMap<String, (usize, u32, u64)>,
    pub warnings: Vec<String>,
}

/// The walker's shared state.
struct Walker<'a> {
    file: &'a StepFile,
    products: &'a Products,
    colours: &'a HashMap<u64, [f64; 3]>,
    out: Walk,
}

/// Where an item sits while walking.
#[derive(Clone)]
struct At {
    /// Root mm ← this representation's mm.
    to_root: DAffine3,
    /// Millimetres and radians per unit of this representation.
    mm: f64,
    rad: f64,
    product: String,
    colour: Option<[f64; 3]>,
    flip: bool,
    depth: usize,
}

/// Every face instance of the file (see the module doc).
pub(crate) fn walk(
    file: &StepFile,
    products: &Products,
    colours: &HashMap<u64, [f64; 3]>,
) -> Res<Walk> {
    let mut w = Walker {
        file,
        products,
        colours,
        out: Walk::default(),
    };
    for root in products.roots() {
        let name = products.names.get(&root).cloned().unwrap_or_default();
        w.definition(root, DAffine3::IDENTITY, &name, 0)?;
    }
    if w.out.instances.is_empty() {
        w.orphans()?;
    }
    Ok(w.out)
}

impl<'a> Walker<'a> {
    fn entity(&self, id: u64) -> Res<EntityRef<'a>> {
        self.file.get(id).map_err(super::attrs::msg)
    }

    /// A product definition: its own shape, then its components.
    fn definition(&mut self, pd: u64, to_root: DAffine3, name: &str, depth: usize) -> Res<()> {
        if depth > MAX_DEPTH {
            let e = self.entity(pd)?;
            return Err(bad(&e, "assembly nested too deeply (a cycle?)"));
        }
        let reps: Vec<u64> = self.products.reps.get(&pd).cloned().unwrap_or_default();
        let mut seen = HashSet::new();
        for r in reps {
            self.representation(r, to_root, name, depth, &mut seen)?;
        }
        let children = self.products.children.get(&pd).cloned().unwrap_or_default();
        for (nauo, child) in children {
            let rel = self
                .products
                .placements
                .get(&nauo)
                .and_then(|v| v.first().copied());
            let placed = match rel {
                Some(rel) => to_root * self.placement(rel, child)?,
                None => {
                    let e = self.entity(nauo)?;
                    self.out.warnings.push(format!(
                        "line {}: #{} NEXT_ASSEMBLY_USAGE_OCCURRENCE has no placement: component drawn unmoved",
                        e.line(),
                        e.id()
                    ));
                    to_root
                }
            };
            let child_name = self.products.names.get(&child).cloned().unwrap_or_default();
            self.definition(child, placed, &child_name, depth + 1)?;
        }
        Ok(())
    }

    /// The transformation (component mm → assembly mm) of a representation relationship.
    fn placement(&self, rel: u64, child: u64) -> Res<DAffine3> {
        let e = self.entity(rel)?;
        let own = part(e, "REPRESENTATION_RELATIONSHIP", 0)?;
        let (r1, r2) = (own.p(2, "rep_1")?.ent()?, own.p(3, "rep_2")?.ent()?);
        let op = part(e, "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION", 0)?
            .p(0, "transformation_operator")?
            .ent()?;
        let child_reps = self.products.all_reps(child);
        let reversed = !child_reps.contains(&r1.id()) && child_reps.contains(&r2.id());
        let (s1, s2) = (
            units::of_representation(r1)?.mm,
            units::of_representation(r2)?.mm,
        );
        let forward = if is(&op, "ITEM_DEFINED_TRANSFORMATION") {
            let own = part(op, "ITEM_DEFINED_TRANSFORMATION", 0)?;
            let a1 = placement_mm(own.p(2, "transform_item_1")?.ent()?, s1)?;
            let a2 = placement_mm(own.p(3, "transform_item_2")?.ent()?, s2)?;
            a2 * a1.inverse()
        } else if is(&op, "CARTESIAN_TRANSFORMATION_OPERATOR") {
            operator_mm(op, s1)?
        } else {
            return Err(bad(&op, "unknown transformation operator"));
        };
        Ok(if reversed { forward.inverse() } else { forward })
    }

    /// A representation's items, then the representations tied to it.
    fn representation(
        &mut self,
        rep: u64,
        to_root: DAffine3,
        name: &str,
        depth: usize,
        seen: &mut HashSet<u64>,
    ) -> Res<()> {
        let home = self.products.owner.get(&rep).copied();
        for r in self.products.linked(rep) {
            if !seen.insert(r) {
                continue;
            }
            // A representation that is another product's shape is placed through that product.
            let owner = self.products.owner.get(&r).copied();
            if r != rep && owner.is_some() && owner != home {
                continue;
            }
            let e = self.entity(r)?;
            let u = units::of_representation(e)?;
            let at = At {
                to_root,
                mm: u.mm,
                rad: u.rad,
                product: name.to_owned(),
                colour: None,
                flip: false,
                depth,
            };
            for item in part(e, "REPRESENTATION", 0)?.p(1, "items")?.ents()? {
                self.item(item, &at)?;
            }
        }
        Ok(())
    }

    /// One representation item (see the module doc for what is drawn).
    fn item(&mut self, e: EntityRef<'a>, at: &At) -> Res<()> {
        if at.depth > MAX_DEPTH {
            return Err(bad(&e, "shapes nested too deeply (a cycle?)"));
        }
        let mut at = at.clone();
        at.depth += 1;
        if let Some(&c) = self.colours.get(&e.id()) {
            at.colour = Some(c);
        }
        let name = e.name();
        if is(&e, "ADVANCED_FACE") || is(&e, "FACE_SURFACE") {
            self.out.instances.push(Instance {
                face: e.id(),
                flip: at.flip,
                to_mm: at.to_root * DAffine3::from_scale(DVec3::splat(at.mm)),
                rad: at.rad,
                product: at.product.clone(),
                colour: at.colour,
            });
            return Ok(());
        }
        let children: Vec<EntityRef<'a>> = match name {
            "MANIFOLD_SOLID_BREP" | "FACETED_BREP" | "BREP_WITH_VOIDS" => {
                let own = part(e, "MANIFOLD_SOLID_BREP", 1)?;
                let mut v = vec![own.p(0, "outer")?.ent()?];
                if is(&e, "BREP_WITH_VOIDS") {
                    v.extend(part(e, "BREP_WITH_VOIDS", 2)?.p(0, "voids")?.ents()?);
                }
                v
            }
            "SHELL_BASED_SURFACE_MODEL" => part(e, name, 1)?.p(0, "sbsm_boundary")?.ents()?,
            "FACE_BASED_SURFACE_MODEL" => part(e, name, 1)?.p(0, "fbsm_faces")?.ents()?,
            "CLOSED_SHELL" | "OPEN_SHELL" | "CONNECTED_FACE_SET" => {
                part(e, "CONNECTED_FACE_SET", 1)?
                    .p(0, "cfs_faces")?
                    .ents()?
            }
            "ORIENTED_CLOSED_SHELL" | "ORIENTED_OPEN_SHELL" | "ORIENTED_FACE" => {
                let own = part(e, name, 2)?;
                at.flip ^= !own.p(1, "orientation")?.flag()?;
                vec![own.p(0, "element")?.ent()?]
            }
            "MAPPED_ITEM" => return self.mapped(e, &at),
            "AXIS2_PLACEMENT_3D" | "AXIS2_PLACEMENT_2D" | "AXIS1_PLACEMENT" => Vec::new(),
            _ => {
                let slot =
                    self.out
                        .not_drawn
                        .entry(e.type_names())
                        .or_insert((0, e.line(), e.id()));
                slot.0 += 1;
                Vec::new()
            }
        };
        for c in children {
            self.item(c, &at)?;
        }
        Ok(())
    }

    /// MAPPED_ITEM: the mapped representation placed by origin → target.
    fn mapped(&mut self, e: EntityRef<'a>, at: &At) -> Res<()> {
        let own = part(e, "MAPPED_ITEM", 1)?;
        let map = own.p(0, "mapping_source")?.ent()?;
        let target = own.p(1, "mapping_target")?.ent()?;
        let m = part(map, "REPRESENTATION_MAP", 0)?;
        let origin = m.p(0, "mapping_origin")?.ent()?;
        let rep = m.p(1, "mapped_representation")?.ent()?;
        let mm = units::of_representation(rep)?.mm;
        let t = if is(&target, "CARTESIAN_TRANSFORMATION_OPERATOR") {
            operator_mm(target, at.mm)?
        } else {
            placement_mm(target, at.mm)?
        };
        let place = t * placement_mm(origin, mm)?.inverse();
        let mut seen = HashSet::new();
        let name = at.product.clone();
        let before = self.out.instances.len();
        self.representation(rep.id(), at.to_root * place, &name, at.depth + 1, &mut seen)?;
        if let Some(c) = at.colour {
            for i in self.out.instances.iter_mut().skip(before) {
                i.colour.get_or_insert(c);
            }
        }
        Ok(())
    }

    /// Without product structure (or none reaching a shape): every representation that holds
    /// shapes and is not only drawn through a MAPPED_ITEM, each once.
    fn orphans(&mut self) -> Res<()> {
        let mut seen = HashSet::new();
        let reps: Vec<u64> = self
            .file
            .entities()
            .filter(|e| is(e, "SHAPE_REPRESENTATION") || e.name() == "REPRESENTATION")
            .map(|e| e.id())
            .filter(|id| !self.products.mapped.contains(id))
            .collect();
        // Without a product, faces are named after the file (FILE_NAME, without folder or
        // extension), or "shape".
        let header = &self.file.header.name;
        let stem = header.rsplit(['/', '\\']).next().unwrap_or("");
        let stem = stem.split('.').next().unwrap_or("").trim();
        let fallback = if stem.is_empty() { "shape" } else { stem };
        for r in reps {
            let name = self
                .products
                .owner
                .get(&r)
                .and_then(|o| self.products.names.get(o))
                .cloned()
                .unwrap_or_else(|| fallback.to_owned());
            self.representation(r, DAffine3::IDENTITY, &name, 0, &mut seen)?;
        }
        Ok(())
    }
}

/// AXIS2_PLACEMENT_3D as local → parent, its location scaled to mm.
fn placement_mm(e: EntityRef<'_>, mm: f64) -> Res<DAffine3> {
    let f = frame(e)?;
    Ok(DAffine3::from_mat3_translation(
        DMat3::from_cols(f.x, f.y, f.z),
        f.origin * mm,
    ))
}

/// CARTESIAN_TRANSFORMATION_OPERATOR(_3D) (ISO 10303-42 §4.4.23): `origin + scale · [a1 a2 a3]`
/// with the axes completed as its `base_axis` function does; translation in mm.
fn operator_mm(e: EntityRef<'_>, mm: f64) -> Res<DAffine3> {
    let own = part(e, "CARTESIAN_TRANSFORMATION_OPERATOR", 2)?;
    let axis = |i, name| -> Res<Option<DVec3>> {
        match own.p(i, name)?.optional() {
            Some(p) => Ok(Some(direction(p.ent()?)?.normalize())),
            None => Ok(None),
        }
    };
    let a1 = axis(0, "axis1")?;
    let a2 = axis(1, "axis2")?;
    let origin = point3(own.p(2, "local_origin")?.ent()?)?;
    let scale = match own.p(3, "scale")?.optional() {
        Some(p) => p.f()?,
        None => 1.0,
    };
    let a3 = if is(&e, "CARTESIAN_TRANSFORMATION_OPERATOR_3D") {
        match part(e, "CARTESIAN_TRANSFORMATION_OPERATOR_3D", 6)?
            .p(0, "axis3")?
            .optional()
        {
            Some(p) => Some(direction(p.ent()?)?.normalize()),
            None => None,
        }
    } else {
        None
    };
    let z = a3.unwrap_or(DVec3::Z);
    let x0 = a1.unwrap_or(if z.x.abs() > 0.99 { DVec3::Y } else { DVec3::X });
    let x = (x0 - x0.dot(z) * z)
        .try_normalize()
        .ok_or_else(|| bad(&e, "axis1 is parallel to axis3"))?;
    let y0 = a2.unwrap_or_else(|| z.cross(x));
    let y = (y0 - y0.dot(z) * z - y0.dot(x) * x)
        .try_normalize()
        .ok_or_else(|| bad(&e, "axis2 is parallel to axis1"))?;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(bad(&e, "scale must be positive"));
    }
    let z = if a3.is_some() { z } else { x.cross(y) };
    Ok(DAffine3::from_mat3_translation(
        DMat3::from_cols(x, y, z) * scale,
        origin * mm,
    ))
}
