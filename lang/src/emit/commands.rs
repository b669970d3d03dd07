use crate::ir::TreeIr;
pub fn emit(_ir: &TreeIr) -> String {
    unimplemented!("written next")
}
