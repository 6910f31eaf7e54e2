//! SM 6.6 descriptor heaps: `ResourceDescriptorHeap[i]` and
//! `SamplerDescriptorHeap[i]`, given a type by the variable they initialize
//! (`Texture2D t = ResourceDescriptorHeap[i];`) or a cast.
//!
//! Each resource type taken from the heap is an unbounded array of that type
//! (as in DXC's Vulkan mapping), and all of them share one binding: set 0,
//! the first binding after the module's own; the sampler heap has the next.
//! The application binds the heap there (descriptor indexing, with mutable
//! descriptors where types mix).

use super::*;

impl<'a> Lowerer<'a> {
    /// `(heap, index)` when `e` is `ResourceDescriptorHeap[index]` or
    /// `SamplerDescriptorHeap[index]`.
    pub(super) fn heap_index(e: &'a Expr) -> Option<(bool, &'a Expr)> {
        let ExprKind::Index(base, idx) = &e.kind else {
            return None;
        };
        match &base.kind {
            ExprKind::Ident(n) if n == "ResourceDescriptorHeap" => Some((false, idx)),
            ExprKind::Ident(n) if n == "SamplerDescriptorHeap" => Some((true, idx)),
            _ => None,
        }
    }

    /// The element `idx` of the heap seen as an array of `t`.
    pub(super) fn heap_place(
        &mut self,
        sampler: bool,
        idx: &'a Expr,
        t: &Ty,
        pos: Pos,
    ) -> Result<Place> {
        let is_sampler = matches!(t, Ty::Sampler | Ty::SamplerCmp);
        if sampler != is_sampler || !t.is_resource() || matches!(t, Ty::Array(..) | Ty::RtArray(_))
        {
            return Err(Error::new(
                pos,
                format!(
                    "a `{}` cannot come from the {} heap",
                    self.ty_name(t),
                    if sampler { "sampler" } else { "resource" }
                ),
            ));
        }
        let var = match self.heap_vars.get(t) {
            Some(v) => *v,
            None => {
                let binding = if sampler {
                    self.heap_bindings.1
                } else {
                    self.heap_bindings.0
                };
                let name = if sampler {
                    "SamplerDescriptorHeap"
                } else {
                    "ResourceDescriptorHeap"
                };
                let var =
                    self.resource_var(&Ty::RtArray(Box::new(t.clone())), &[], Some(binding), name)?;
                self.heap_vars.insert(t.clone(), var);
                var
            }
        };
        self.use_global(var);
        let (class, layout) = self.param_class(t);
        let heap = Place::Ptr {
            ptr: var,
            ty: Ty::RtArray(Box::new(t.clone())),
            layout,
            class,
        };
        let iv = self.expr(idx)?;
        self.index(heap, iv, idx, pos)
    }
}
