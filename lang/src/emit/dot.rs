use crate::ir::TreeIr;
pub fn emit_dot(_ir: &TreeIr) -> String {
    unimplemented!("written next")
}
pub fn emit_mermaid(_ir: &TreeIr) -> String {
    unimplemented!("written next")
}
