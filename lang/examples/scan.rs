fn main() {
    use btc_lang::pddl::*;
    use btc_lang::source::Sources;
    for dir in std::fs::read_dir("../../shared/corpus/ipc").unwrap() {
        let dir = dir.unwrap().path();
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().map_or(false, |e| e == "pddl"))
            .collect();
        files.sort();
        let mut sources = Sources::new();
        let mut dom = None;
        for f in &files {
            let name = f.file_name().unwrap().to_str().unwrap();
            if !name.contains("domain") {
                continue;
            }
            let text = std::fs::read_to_string(f).unwrap();
            let id = sources.add(f.display().to_string(), text.clone());
            let (d, mut diags) = parse_domain(&text, id);
            if let Some(d) = d {
                let (ix, cd) = check_domain(&d);
                diags.extend(cd);
                dom = Some((d, ix));
            }
            for d in &diags {
                println!("{}", btc_lang::render::to_short(d, &sources));
            }
        }
        for f in &files {
            let name = f.file_name().unwrap().to_str().unwrap();
            if name.contains("domain") {
                continue;
            }
            let text = std::fs::read_to_string(f).unwrap();
            let id = sources.add(f.display().to_string(), text.clone());
            let (p, mut diags) = parse_problem(&text, id);
            if let (Some(p), Some((d, ix))) = (p, &dom) {
                let (_, cd) = check_problem(&p, d, ix);
                diags.extend(cd);
            }
            for d in &diags {
                println!("{}", btc_lang::render::to_short(d, &sources));
            }
        }
    }
}
