use super::names::*;
use super::*;

#[test]
fn strings_are_escaped() {
    assert_eq!(py_str("plain"), "\"plain\"");
    assert_eq!(py_str("a\"b"), "\"a\\\"b\"");
    assert_eq!(py_str("a'b"), "\"a'b\"");
    assert_eq!(py_str("'''"), "\"'''\"");
    assert_eq!(py_str("\"\"\""), "\"\\\"\\\"\\\"\"");
    assert_eq!(py_str("back\\slash"), "\"back\\\\slash\"");
    assert_eq!(py_str("\\"), "\"\\\\\"");
    assert_eq!(py_str("line\nbreak\r\t"), "\"line\\nbreak\\r\\t\"");
    assert_eq!(py_str("</script>"), "\"</script>\"");
    assert_eq!(py_str("ü"), "\"\\xfc\"");
    assert_eq!(py_str("日本"), "\"\\u65e5\\u672c\"");
    assert_eq!(py_str("🤖"), "\"\\U0001f916\"");
    assert_eq!(py_str("\0\u{7f}\u{2028}"), "\"\\x00\\x7f\\u2028\"");
    assert_eq!(py_str(""), "\"\"");
}

#[test]
fn escaped_strings_are_one_ascii_line() {
    let hostile = "x\"\"\"y'''z\\\n# comment\r\n</b>\u{2028}\u{85}ü日本\\";
    let lit = py_str(hostile);
    assert!(lit.is_ascii());
    assert!(!lit.contains('\n') && !lit.contains('\r'));
    assert!(lit.starts_with('"') && lit.ends_with('"'));
    // No unescaped quote inside: every `"` in the body follows a `\`
    // that is itself not escaped.
    let body = &lit[1..lit.len() - 1];
    let mut escaped = false;
    for c in body.chars() {
        if escaped {
            escaped = false;
        } else if c == '\\' {
            escaped = true;
        } else {
            assert_ne!(c, '"', "unescaped quote in {lit}");
        }
    }
    assert!(!escaped, "dangling backslash in {lit}");
}

#[test]
fn identifiers_are_sanitized() {
    assert_eq!(py_ident("MoveTo"), "MoveTo");
    assert_eq!(py_ident("move_to2"), "move_to2");
    assert_eq!(py_ident("Move-To"), "Move_To");
    assert_eq!(py_ident("3d"), "Node3d");
    assert_eq!(py_ident(""), "Node");
    assert_eq!(py_ident("_private"), "Node_private");
    assert_eq!(py_ident("__name__"), "Node__name__");
    assert_eq!(py_ident("class"), "class_");
    assert_eq!(py_ident("None"), "None_");
    assert_eq!(py_ident("a\"b'''c\"\"\"d"), "a_b___c___d");
    assert_eq!(py_ident("x\ny</z>"), "x_y__z_");
    assert_eq!(py_ident("Größe"), "Gr__e");
    assert_eq!(py_ident("日本"), "Node__");
    assert_eq!(py_ident("a\\b"), "a_b");
    for s in ["", "日本", "\"", "1", "a b", "\n", "if", "🤖x"] {
        let id = py_ident(s);
        assert!(id.starts_with(|c: char| c.is_ascii_alphabetic()), "{id}");
        assert!(id.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'));
        assert!(!PY_KEYWORDS.contains(&id.as_str()));
    }
}

#[test]
fn identifiers_are_unique() {
    let mut names = Names::reserving(RESERVED);
    assert_eq!(names.fresh("Move-To"), "Move_To");
    assert_eq!(names.fresh("Move To"), "Move_To_2");
    assert_eq!(names.fresh("Move_To"), "Move_To_3");
    assert_eq!(names.fresh("日本"), "Node__");
    assert_eq!(names.fresh("中国"), "Node___2");
    // Names the module uses itself are never handed out.
    assert_eq!(names.fresh("print"), "print_2");
    assert_eq!(names.fresh("KnowledgeBase"), "KnowledgeBase_2");
    assert_eq!(names.fresh("py_trees"), "py_trees_2");
}

#[test]
fn module_names_are_imported_safely() {
    assert_eq!(
        module_import("my_nodes"),
        ("my_nodes".into(), "import my_nodes\n".into())
    );
    assert_eq!(module_import("pkg.nodes").0, "pkg.nodes");
    for clash in ["sys", "WORLD", "py_trees.x", "_reset", "main"] {
        assert_eq!(module_import(clash).0, "NODE_MODULE", "{clash}");
    }
    let (prefix, import) = module_import("my-nodes\"\nimport os");
    assert_eq!(prefix, "NODE_MODULE");
    assert!(import.contains("importlib.import_module(\"my-nodes\\\"\\nimport os\")"));
}

/// Every top-level name the runtime defines is reserved, so no generated
/// class can shadow one of them (in `--runtime inline`, a shadowed name
/// would break the runtime itself).
#[test]
fn the_runtime_names_are_reserved() {
    let mut missing = Vec::new();
    for line in RUNTIME.lines() {
        let name = line
            .strip_prefix("class ")
            .or_else(|| line.strip_prefix("def "))
            .map(|r| r.split(['(', ':']).next().unwrap_or_default())
            .or_else(|| line.split_once(" = ").map(|(n, _)| n))
            .unwrap_or_default();
        let is_name = name.starts_with(|c: char| c.is_ascii_alphabetic())
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if is_name && !RESERVED.contains(&name) {
            missing.push(name.to_owned());
        }
    }
    assert!(missing.is_empty(), "not in RESERVED: {missing:?}");
}

#[test]
fn empty_conjunctions_are_tuples() {
    use btc_pddl::logic::Formula;
    // `(and)`, the empty precondition: `(":and")` would be a Python string.
    assert_eq!(encode::formula(&Formula::And(Vec::new())), "(\":and\",)");
    assert_eq!(encode::formula(&Formula::Or(Vec::new())), "(\":or\",)");
}
