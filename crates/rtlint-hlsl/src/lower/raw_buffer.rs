//! `vk::RawBufferLoad<T>(address[, alignment])`: a load through a 64-bit
//! device address, as DXC lowers it: `OpConvertUToPtr` to a
//! `PhysicalStorageBuffer` pointer and an `Aligned` `OpLoad`, in a module
//! whose addressing model is `PhysicalStorageBuffer64`.

use super::*;

impl<'a> Lowerer<'a> {
    /// `vk::RawBufferLoad<T>(...)` (`targ` is `T`) or `vk::RawBufferLoad(...)`
    /// (a `uint`).
    pub(super) fn raw_buffer_load(
        &mut self,
        targ: Option<&TArg>,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Val> {
        const NAME: &str = "vk::RawBufferLoad";
        let t = match targ {
            None => Ty::ScalarKind(ScalarKind::Uint),
            Some(TArg::Type(t)) => {
                let ns = self.f.cur_ns.clone();
                self.resolve_ty(t, &ns)?
            }
            Some(_) => return Err(Error::new(pos, "`vk::RawBufferLoad<T>` takes a type")),
        };
        let scalar = match &t {
            Ty::ScalarKind(s) | Ty::Vec(s, _) if *s != ScalarKind::Bool => *s,
            _ => {
                return Err(unsupported(
                    pos,
                    format!(
                        "`vk::RawBufferLoad<{}>` (scalars and vectors only)",
                        self.ty_name(&t)
                    ),
                )
                .len(NAME.len() as u32))
            }
        };
        if args.is_empty() || args.len() > 2 {
            return Err(Error::new(
                pos,
                format!("`{NAME}` takes 1 or 2 argument(s), {} given", args.len()),
            )
            .len(NAME.len() as u32));
        }
        let addr = self.expr_as(&args[0], &Ty::ScalarKind(ScalarKind::Uint64))?;
        // DXC's default alignment is 4; a given one must be a constant power of two.
        let align = match args.get(1) {
            None => 4,
            Some(e) => {
                let n = self.const_int(e)?;
                match u32::try_from(n) {
                    Ok(a) if a.is_power_of_two() => a,
                    _ => {
                        return Err(Error::new(
                            e.pos,
                            format!("the alignment must be a power of two, not {n}"),
                        ))
                    }
                }
            }
        };
        // Natural alignment at least, as Vulkan requires of the load.
        let align = align.max(scalar.size());
        self.physical_storage_buffer();
        let tid = self.ty_id(&t)?;
        let pty = self
            .b
            .type_pointer(None, StorageClass::PhysicalStorageBuffer, tid);
        let ptr = self.op(Op::ConvertUToPtr, pty, &[addr.id])?;
        let id = self.b.load(
            tid,
            None,
            ptr,
            Some(spirv::MemoryAccess::ALIGNED),
            [Operand::LiteralBit32(align)],
        )?;
        Ok(Val { id, ty: t })
    }

    /// The capability and extension of device addresses; `finish` sets the
    /// addressing model.
    fn physical_storage_buffer(&mut self) {
        self.cap(Capability::PhysicalStorageBufferAddresses);
        self.cap(Capability::Int64);
        self.ext("SPV_KHR_physical_storage_buffer");
        self.physical_addressing = true;
    }
}
