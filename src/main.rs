fn main() {
    let path = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let lang = rtlint::front::Language::from_path(&path).unwrap();
    let p = rtlint::front::load(&path, lang).unwrap();
    for e in &p.entry_points {
        println!("entry {} {:?}", e.name, e.stage);
    }
    for g in &p.globals {
        println!(
            "global {:?} {:?} ty={} loc={:?}",
            g.name,
            g.storage,
            p.type_name(g.ty),
            p.var_location(g.id).map(|l| l.to_string())
        );
    }
    for s in &p.sites {
        println!(
            "site {:?} {:?} {:?} payload={:?} loc={:?}",
            s.kind,
            p.functions[s.function].name,
            s.trace,
            s.payload,
            p.site_location(s.inst).map(|l| l.to_string())
        );
    }
    for (d, pos) in &p.decl_pos {
        println!("decl {:?} {}", d, p.location(*pos));
    }
}
