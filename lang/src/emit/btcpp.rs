use crate::ir::TreeIr;
pub fn emit(_ir: &TreeIr, _inline: bool) -> String {
    unimplemented!("written next")
}
