use crate::ir::TreeIr;
pub fn emit(_ir: &TreeIr, _node_module: Option<&str>) -> String {
    unimplemented!("written by the py_trees helper")
}
