//! Defines and instances: a `[define.NAME]` placed by a top-level `instance` is
//! compiled once into an object all its instances share; an `instance` inside a define
//! copies the other define's content in place, which is where cycles are caught. Defines
//! that nothing expanded are checked all the same, and those that no instance names
//! anywhere in the file are warned about.

use super::super::format::{ObjectDef, SceneFile, Spanned};
use super::objects::{Ctx, Sink};
use super::types::Ty;
use super::{Builder, DisplayPrefix, LOG_TARGET, R, did_you_mean};
use crate::scene::{Geometry, Instance};
use std::collections::HashSet;

impl<'a> Builder<'a, '_> {
    /// The define named by `of`: its name and content.
    pub(super) fn lookup_define(
        &self,
        of: &Spanned<String>,
    ) -> R<(&'a str, &'a Spanned<ObjectDef>)> {
        let name = of.get_ref().as_str();
        match self.file.define.get_key_value(name) {
            Some((k, v)) => Ok((k.as_str(), v)),
            None => {
                let hint = if self.file.define.is_empty() {
                    " (the file has no `[define.NAME]`)".to_string()
                } else {
                    did_you_mean(name, self.file.define.keys().map(String::as_str))
                };
                Err(self.err(of.span(), format!("unknown define `{name}`{hint}")))
            }
        }
    }

    /// Start expanding define `name` (named by `of`), unless that is a cycle.
    pub(super) fn enter_define(&mut self, name: &'a str, of: &Spanned<String>) -> R<()> {
        self.expanded.insert(name);
        if self.define_stack.contains(&name) {
            let mut chain: Vec<&str> = self.define_stack.clone();
            chain.push(name);
            return Err(self.err(
                of.span(),
                format!(
                    "define `{name}` contains an instance of itself: {}",
                    chain.join(" → ")
                ),
            ));
        }
        self.define_stack.push(name);
        Ok(())
    }

    /// `instance`: at the top level, the define's shared object placed under the
    /// instance's transform; inside a define, the define's content copied in place.
    pub(super) fn instance(
        &mut self,
        node: &'a Spanned<ObjectDef>,
        inner: Ctx,
        sink: &mut Sink,
    ) -> R<()> {
        let of = self.need(&node.get_ref().of, "of", node, Ty::Instance)?;
        let (name, def) = self.lookup_define(of)?;
        if sink.in_define() {
            self.enter_define(name, of)?;
            self.walk(def, inner, sink)?;
            self.define_stack.pop();
            return Ok(());
        }
        let object = match self.compiled.get(name) {
            Some(&o) => o,
            None => self.compile_define(name, def, of)?,
        };
        if let Some(object) = object {
            let xform = self.check_invertible(&inner.xform, node.get_ref().ty.span())?;
            let material = self.material_or_fallback(inner.material, sink);
            self.instances.push(Instance {
                object,
                xform,
                material,
            });
        }
        Ok(())
    }

    /// Define `name` (content `def`, first named by `of`) compiled into an object of
    /// the scene: its index, or `None` when it holds no primitive.
    fn compile_define(
        &mut self,
        name: &'a str,
        def: &'a Spanned<ObjectDef>,
        of: &Spanned<String>,
    ) -> R<Option<u32>> {
        self.enter_define(name, of)?;
        let mut g = Geometry::default();
        self.walk(def, Ctx::ROOT, &mut Sink::Object(&mut g))?;
        self.define_stack.pop();
        let o = if g.prim_count() == 0 {
            log::warn!(
                target: LOG_TARGET,
                "{}: define `{name}` holds no primitive; its instances are left out",
                self.at(def.span()).display_prefix()
            );
            None
        } else {
            self.objects.push(g);
            Some(self.objects.len() as u32 - 1)
        };
        self.compiled.insert(name, o);
        Ok(o)
    }

    /// Defines that nothing expanded, checked all the same (in file order), so that an
    /// error in one does not wait until it is first used; those that no instance names
    /// anywhere are warned about.
    pub(super) fn check_unused_defines(&mut self) -> R<()> {
        let file = self.file;
        let named = instanced_names(file);
        let mut defines: Vec<_> = file.define.iter().collect();
        defines.sort_by_key(|(_, d)| d.span().start);
        for (name, def) in defines {
            if !named.contains(name.as_str()) {
                log::warn!(
                    target: LOG_TARGET,
                    "{}: define `{name}` is never instanced",
                    self.at(def.span()).display_prefix()
                );
            }
            if !self.expanded.contains(name.as_str()) {
                self.expanded.insert(name);
                let mut scratch = Geometry::default();
                self.define_stack.push(name);
                self.walk(def, Ctx::ROOT, &mut Sink::Object(&mut scratch))?;
                self.define_stack.pop();
            }
        }
        Ok(())
    }
}

/// The names of the defines that some `instance` names, anywhere in `file`: among its
/// objects and inside every define, placed or not, at any depth (CSG operands and
/// group children alike).
fn instanced_names(file: &SceneFile) -> HashSet<&str> {
    let mut names = HashSet::new();
    let mut todo: Vec<&ObjectDef> = file
        .objects
        .iter()
        .chain(file.define.values())
        .map(Spanned::get_ref)
        .collect();
    while let Some(o) = todo.pop() {
        if o.ty.get_ref() == Ty::Instance.name() {
            if let Some(of) = &o.of {
                names.insert(of.get_ref().as_str());
            }
        }
        if let Some(children) = &o.children {
            todo.extend(children.get_ref().iter().map(Spanned::get_ref));
        }
    }
    names
}
