//! The product structure (ISO 10303-41 product definition schema, AP203/AP214/AP242
//! assembly structure), indexed in one pass over the file.
//!
//! PRODUCT ← PRODUCT_DEFINITION_FORMATION ← PRODUCT_DEFINITION ← PRODUCT_DEFINITION_SHAPE ←
//! SHAPE_DEFINITION_REPRESENTATION → a shape representation: a part's geometry. An assembly's
//! components are NEXT_ASSEMBLY_USAGE_OCCURRENCEs (relating = the assembly, related = the
//! component); each is placed by a CONTEXT_DEPENDENT_SHAPE_REPRESENTATION whose
//! representation_relation is a REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION between the
//! component's and the assembly's representations. Plain SHAPE_REPRESENTATION_RELATIONSHIPs
//! (no transformation) tie a part's representation to the one holding its geometry.

use std::collections::{HashMap, HashSet};

use crate::formats::step::{EntityRef, StepFile};

use super::attrs::{P, Res, is, part};

/// The indexed product structure.
#[derive(Default, Debug)]
pub(crate) struct Products {
    /// PRODUCT_DEFINITION → its shape representations.
    pub reps: HashMap<u64, Vec<u64>>,
    /// PRODUCT_DEFINITION → its components `(NAUO id, component PRODUCT_DEFINITION)`.
    pub children: HashMap<u64, Vec<(u64, u64)>>,
    /// NAUO id → the representation relationships placing it.
    pub placements: HashMap<u64, Vec<u64>>,
    /// Representation → representations tied to it without a transformation (both ways).
    pub links: HashMap<u64, Vec<u64>>,
    /// Every PRODUCT_DEFINITION that is some NAUO's component.
    pub components: HashSet<u64>,
    /// PRODUCT_DEFINITION → product name.
    pub names: HashMap<u64, String>,
    /// Representation → the product definition whose shape it is.
    pub owner: HashMap<u64, u64>,
    /// Product definitions in file order.
    pub definitions: Vec<u64>,
    /// Representations that a REPRESENTATION_MAP maps (drawn only through a MAPPED_ITEM).
    pub mapped: HashSet<u64>,
}

/// Indexes the file (see the module doc).
pub(crate) fn index(file: &StepFile) -> Res<Products> {
    let mut p = Products::default();
    for e in file.entities() {
        if is(&e, "SHAPE_DEFINITION_REPRESENTATION") {
            let own = part(e, "PROPERTY_DEFINITION_REPRESENTATION", 0)?;
            let pds = own.p(0, "definition")?.ent()?;
            let rep = own.p(1, "used_representation")?.ent()?;
            let def = part(pds, "PROPERTY_DEFINITION", 0)?
                .p(2, "definition")?
                .ent()?;
            if is(&def, "PRODUCT_DEFINITION") {
                p.reps.entry(def.id()).or_default().push(rep.id());
                p.owner.entry(rep.id()).or_insert(def.id());
            }
        } else if is(&e, "NEXT_ASSEMBLY_USAGE_OCCURRENCE") {
            let own = part(e, "PRODUCT_DEFINITION_RELATIONSHIP", 0)?;
            let parent = own.p(3, "relating_product_definition")?.ent()?;
            let child = own.p(4, "related_product_definition")?.ent()?;
            p.children
                .entry(parent.id())
                .or_default()
                .push((e.id(), child.id()));
            p.components.insert(child.id());
        } else if is(&e, "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION") {
            let own = part(e, "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION", 0)?;
            let rel = own.p(0, "representation_relation")?.ent()?;
            let pds = own.p(1, "represented_product_relation")?.ent()?;
            let def = part(pds, "PROPERTY_DEFINITION", 0)?
                .p(2, "definition")?
                .ent()?;
            p.placements.entry(def.id()).or_default().push(rel.id());
        } else if is(&e, "REPRESENTATION_RELATIONSHIP")
            && !is(&e, "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION")
        {
            let own = part(e, "REPRESENTATION_RELATIONSHIP", 0)?;
            let (a, b) = (own.p(2, "rep_1")?.ent()?, own.p(3, "rep_2")?.ent()?);
            p.links.entry(a.id()).or_default().push(b.id());
            p.links.entry(b.id()).or_default().push(a.id());
        } else if is(&e, "PRODUCT_DEFINITION") {
            p.definitions.push(e.id());
            p.names.insert(e.id(), product_name(e)?);
        } else if is(&e, "REPRESENTATION_MAP") {
            let own = part(e, "REPRESENTATION_MAP", 0)?;
            p.mapped.insert(
                own.p(1, "mapped_representation")?
                    .reference()
                    .map_err(super::attrs::msg)?,
            );
        }
    }
    Ok(p)
}

/// PRODUCT.name through the formation (the id where the name is empty).
fn product_name(pd: EntityRef<'_>) -> Res<String> {
    let own = part(pd, "PRODUCT_DEFINITION", 0)?;
    let pdf = own.p(2, "formation")?.ent()?;
    let product = part(pdf, "PRODUCT_DEFINITION_FORMATION", 0)?
        .p(2, "of_product")?
        .ent()?;
    let pr = part(product, "PRODUCT", 0)?;
    let name = pr.p(1, "name")?.text()?;
    Ok(if name.trim().is_empty() {
        pr.p(0, "id")?.text()?.to_owned()
    } else {
        name.to_owned()
    })
}

impl Products {
    /// Root product definitions: not a component of any assembly, in file order.
    #[must_use]
    pub(crate) fn roots(&self) -> Vec<u64> {
        self.definitions
            .iter()
            .copied()
            .filter(|d| !self.components.contains(d))
            .collect()
    }

    /// A representation and those tied to it by plain relationships, transitively.
    #[must_use]
    pub(crate) fn linked(&self, rep: u64) -> HashSet<u64> {
        let mut seen = HashSet::from([rep]);
        let mut todo = vec![rep];
        while let Some(r) = todo.pop() {
            for &n in self.links.get(&r).map_or(&[][..], Vec::as_slice) {
                if seen.insert(n) {
                    todo.push(n);
                }
            }
        }
        seen
    }

    /// Every representation of product definition `pd`, with those tied to them.
    #[must_use]
    pub(crate) fn all_reps(&self, pd: u64) -> HashSet<u64> {
        let mut out = HashSet::new();
        for &r in self.reps.get(&pd).map_or(&[][..], Vec::as_slice) {
            out.extend(self.linked(r));
        }
        out
    }
}
