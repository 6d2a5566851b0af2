#[test]
fn list_all() {
    let mut all = std::collections::BTreeSet::new();
    for f in ["sim_lathe", "sim_mill", "sim_mill_802d"] {
        let text = std::fs::read_to_string(format!(
            "{}/../../launch_configs/{f}.yaml",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let cfg = cnc_runtime::LaunchConfig::from_yaml(&text).unwrap();
        for (n, v) in cnc_runtime::parameters::list(&cfg) {
            let generic = n
                .split('.')
                .map(|p| {
                    if p.len() == 1 && p.chars().all(|c| c.is_ascii_uppercase()) {
                        "*"
                    } else {
                        p
                    }
                })
                .collect::<Vec<_>>()
                .join(".");
            all.insert(format!("{generic} = {v}"));
        }
    }
    let mut last = String::new();
    for a in all {
        let n = a.split(" = ").next().unwrap().to_string();
        if n != last {
            println!("{a}");
            last = n;
        }
    }
}
