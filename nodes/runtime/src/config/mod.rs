//! The launch config: one YAML file describes the machine, the network and the nodes.
//! The machine section (what the control's setting pages hold) is `cnc_machine`'s, `nodes.rs`
//! the sections of the cell's nodes (network, servo, simulator, PLC, recorder, HMI, real
//! time), `files.rs` reading the file and the files it names; the ratings are
//! [`crate::limits`].

mod files;
mod nodes;

pub use cnc_machine::machine::*;
pub use nodes::*;

use serde::Deserialize;

/// Top level of `launch_configs/*.yaml`.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LaunchConfig {
    pub machine: MachineConfig,
    #[serde(default)]
    pub network: NetworkConfig,
    #[serde(default)]
    pub servo: ServoConfig,
    #[serde(default)]
    pub sim: SimConfig,
    #[serde(default)]
    pub plc: PlcConfig,
    #[serde(default)]
    pub recorder: RecorderConfig,
    #[serde(default)]
    pub hmi: HmiConfig,
    #[serde(default)]
    pub realtime: RealtimeConfig,
    /// The machine builder's ratings (travel, drives, spindle): set by this file only,
    /// never a parameter ([`crate::limits`]).
    #[serde(default)]
    pub limits: crate::limits::MachineLimits,
}

impl LaunchConfig {
    /// Every section's rules, then the machine against its ratings. Called for the file as
    /// read and for every parameter write ([`crate::parameters::set`]).
    pub(crate) fn validate(&self) -> Result<(), String> {
        self.machine.validate()?;
        self.limits.check(&self.machine.axes)?;
        crate::parameters::check_ranges(self)?;
        nodes::validate(self)
    }

    pub fn axis_index(&self, name: &str) -> Option<usize> {
        self.machine.axes.iter().position(|a| a.name == name)
    }

    /// Power-on slide positions (X as radius).
    pub fn home_slide(&self) -> Vec<f64> {
        self.machine
            .axes
            .iter()
            .map(|a| a.home * a.scale())
            .collect()
    }

    /// Where the simulated slides stand at power-on, slide travel ([`AxisEntry::power_on`]).
    pub fn power_on_slide(&self) -> Vec<f64> {
        self.machine
            .axes
            .iter()
            .map(|a| a.power_on() * a.scale())
            .collect()
    }

    /// The axis address letters in machine order, e.g. `['X', 'Z']`.
    pub fn axis_letters(&self) -> Vec<char> {
        self.machine.axis_letters()
    }

    /// Per axis: programmed and displayed in diameter.
    pub fn diameter_axes(&self) -> Vec<bool> {
        self.machine.diameter_axes()
    }

    /// The second reference point per axis (G30), display units.
    pub fn second_reference(&self) -> Vec<f64> {
        self.machine.second_reference()
    }

    /// Each axis's fixed points (G75), machine coordinates, display units.
    pub fn fixed_points(&self) -> Vec<Vec<f64>> {
        self.machine.fixed_points()
    }

    /// Power-on position in display units.
    pub fn home(&self) -> Vec<f64> {
        self.machine.home()
    }

    /// Axis indices in reference-return order (`machine.reference_order`, D68): the named
    /// ones first, then the rest; by default Z first on a machine with a Y axis.
    pub fn reference_order(&self) -> Vec<usize> {
        let axes = &self.machine.axes;
        let mut names = self.machine.reference_order.clone();
        if names.is_empty() && axes.iter().any(|a| a.name == "Y") {
            names.push("Z".into());
        }
        let mut order: Vec<usize> = names
            .iter()
            .filter_map(|n| axes.iter().position(|a| &a.name == n))
            .collect();
        for i in 0..axes.len() {
            if !order.contains(&i) {
                order.push(i);
            }
        }
        order
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mill's config with `second_reference: z` on its Z axis.
    fn mill_with_second_reference(z: &str) -> Result<LaunchConfig, String> {
        let text = include_str!("../../../../launch_configs/sim_mill.yaml").replace(
            "max: 100.0, home: 0.0,",
            &format!("max: 100.0, home: 0.0, second_reference: {z},"),
        );
        LaunchConfig::from_yaml(&text)
    }

    #[test]
    fn the_second_reference_point_must_lie_within_the_axis_travel() {
        let cfg = mill_with_second_reference("80.0").expect("within travel");
        assert_eq!(cfg.second_reference(), [0.0, 0.0, 80.0]);
        let e = mill_with_second_reference("150.0").unwrap_err();
        assert!(e.contains("second_reference 150"), "{e}");
    }

    /// G75's fixed points (D102): at most four per axis, each within the axis's travel.
    #[test]
    fn fixed_points_are_at_most_four_within_the_travel() {
        let with = |points: &str| {
            let text = include_str!("../../../../launch_configs/sim_mill.yaml").replace(
                "max: 100.0, home: 0.0,",
                &format!("max: 100.0, home: 0.0, fixed_points: {points},"),
            );
            LaunchConfig::from_yaml(&text)
        };
        let cfg = with("[90.0, -10.0]").expect("within travel");
        assert_eq!(cfg.fixed_points()[2], [90.0, -10.0]);
        assert!(cfg.fixed_points()[0].is_empty());
        for bad in ["[150.0]", "[1.0, 2.0, 3.0, 4.0, 5.0]"] {
            let e = with(bad).unwrap_err();
            assert!(e.contains("fixed_points"), "{bad}: {e}");
        }
    }

    /// The simulated probe's boxes (D116): as many finite bounds below as above, in order.
    #[test]
    fn probe_boxes_need_ordered_finite_bounds() {
        let with = |boxes: &str| {
            let text = include_str!("../../../../launch_configs/sim_mill_802d.yaml").replacen(
                "sim:\n",
                &format!("sim:\n  probe: {boxes}\n"),
                1,
            );
            LaunchConfig::from_yaml(&text)
        };
        let cfg = with("[{min: [0, 0, -10], max: [100, 80, 60]}]").expect("a box");
        assert_eq!(cfg.sim.probe[0].max, vec![100.0, 80.0, 60.0]);
        for bad in [
            "[{min: [0, 0], max: [1, 1, 1]}]",
            "[{min: [5, 0, 0], max: [1, 1, 1]}]",
            "[{min: [.nan, 0, 0], max: [1, 1, 1]}]",
            "[{min: [], max: []}]",
        ] {
            let e = with(bad).unwrap_err();
            assert!(e.contains("sim.probe[0]"), "{bad}: {e}");
        }
    }

    /// Issue 45 item 10: off loopback, who may move the machine is named, not assumed.
    #[test]
    fn dds_off_loopback_needs_the_allowed_clients_named() {
        let text = include_str!("../../../../launch_configs/sim_lathe.yaml")
            .replace("  allowed_clients: [\"*\"]\n", "");
        let cfg = LaunchConfig::from_yaml(&text).expect("loopback: anyone");
        assert_eq!(cfg.hmi.allowed_clients(), ["*"]);
        let off = text.replace("interfaces: [127.0.0.1]", "interfaces: [10.0.0.5]");
        let e = LaunchConfig::from_yaml(&off).unwrap_err();
        assert!(
            e.contains("hmi.allowed_clients") && e.contains("10.0.0.5"),
            "{e}"
        );
        let deliberate = off.replace("hmi:\n", "hmi:\n  allowed_clients: [\"*\"]\n");
        assert!(LaunchConfig::from_yaml(&deliberate).is_ok());
        let named = off.replace("hmi:\n", "hmi:\n  allowed_clients: [/cell/supervisor]\n");
        let cfg = LaunchConfig::from_yaml(&named).expect("named");
        assert_eq!(cfg.hmi.allowed_clients(), ["/cell/supervisor"]);
    }

    /// The simulated machine's mechanical stops (D118): on a machine axis, within its travel.
    #[test]
    fn fixed_stops_are_on_an_axis_within_its_travel() {
        let with = |stops: &str| {
            let text = include_str!("../../../../launch_configs/sim_mill_802d.yaml").replacen(
                "sim:\n",
                &format!("sim:\n  fixed_stops: {stops}\n"),
                1,
            );
            LaunchConfig::from_yaml(&text)
        };
        let cfg = with("[{axis: Z, at: 95.0}]").expect("a stop");
        assert_eq!(cfg.sim.fixed_stops[0].at, 95.0);
        for bad in ["[{axis: Q, at: 1.0}]", "[{axis: Z, at: 900.0}]"] {
            let e = with(bad).unwrap_err();
            assert!(e.contains("sim.fixed_stops[0]"), "{bad}: {e}");
        }
    }

    /// The turn-mill's live tool (D142): an axis letter no slide nor C uses, a top speed and
    /// time constant above 0; the C axis's rates above 0 (D141).
    #[test]
    fn the_live_tool_is_an_axis_of_its_own_with_a_speed() {
        let text = include_str!("../../../../launch_configs/sim_turnmill.yaml");
        let cfg = LaunchConfig::from_yaml(text).expect("sim_turnmill");
        let tool = cfg.machine.live_tool.as_ref().expect("a live tool");
        assert_eq!(
            (tool.number(), tool.acceleration().round()),
            (Some(4), 62762.0)
        );
        let live = "live_tool: { axis: A, max_rpm: 2500.0, time_constant: 0.239 }";
        for bad in [
            "live_tool: { axis: X, max_rpm: 2500.0, time_constant: 0.239 }",
            "live_tool: { axis: C, max_rpm: 2500.0, time_constant: 0.239 }",
            "live_tool: { axis: Q, max_rpm: 2500.0, time_constant: 0.239 }",
            "live_tool: { axis: A, max_rpm: 0.0, time_constant: 0.239 }",
            "live_tool: { axis: A, max_rpm: 2500.0, time_constant: 0.0 }",
            "c_axis: { max_velocity: 0.0, max_acceleration: 100.0 }",
        ] {
            let e = LaunchConfig::from_yaml(&text.replacen(live, bad, 1)).unwrap_err();
            assert!(
                e.contains("machine.live_tool") || e.contains("machine.c_axis"),
                "{bad}: {e}"
            );
        }
    }

    /// The MSG service's file (D120): taken from the config's folder, one of the manual's
    /// three sizes.
    #[test]
    fn the_msg_service_file_is_found_from_the_config_and_has_one_of_three_sizes() {
        let text = include_str!("../../../../launch_configs/sim_mill.yaml");
        let with = |kib: u32| {
            let t = text.replacen(
                "machine:\n",
                &format!("machine:\n  msg_file: msg.txt\n  msg_file_kib: {kib}\n"),
                1,
            );
            LaunchConfig::from_yaml_in(&t, std::path::Path::new("/cfg"), None)
        };
        let cfg = with(100).expect("a msg file");
        assert_eq!(
            cfg.machine.msg_file.as_deref(),
            Some(std::path::Path::new("/cfg/msg.txt"))
        );
        let e = with(50).unwrap_err();
        assert!(e.contains("msg_file_kib"), "{e}");
    }

    /// EXTCALL's drives (D110): one letter each, a folder taken from the config's folder.
    #[test]
    fn external_drives_are_letters_with_folders_from_the_configs_folder() {
        let text = include_str!("../../../../launch_configs/sim_mill.yaml");
        let with = |drives: &str| {
            let t = text.replacen(
                "machine:\n",
                &format!("machine:\n  external_drives: {drives}\n"),
                1,
            );
            LaunchConfig::from_yaml_in(&t, std::path::Path::new("/cfg"), None)
        };
        let cfg = with("{D: cf, G: /media/usb}").expect("drives");
        let d = &cfg.machine.external_drives;
        assert_eq!(d["D"], std::path::Path::new("/cfg/cf"));
        assert_eq!(d["G"], std::path::Path::new("/media/usb"));
        let e = with("{DD: cf}").unwrap_err();
        assert!(e.contains("external_drives"), "{e}");
    }

    /// DDS Security (D113): the keystore from the config's folder; an enclave is a path of
    /// names with its credentials present, else refused with the reason.
    #[test]
    fn a_keystore_is_found_from_the_config_and_an_enclave_needs_its_files() {
        let text = include_str!("../../../../launch_configs/sim_lathe.yaml").replacen(
            "network:\n",
            "network:\n  security: {keystore: ks}\n",
            1,
        );
        let dir = std::env::temp_dir().join(format!("cnc_ks_cfg_{}", std::process::id()));
        let cfg = LaunchConfig::from_yaml_in(&text, &dir, None).expect("config");
        let sec = cfg
            .network
            .effective_security()
            .unwrap()
            .expect("security on");
        assert_eq!(sec.keystore, dir.join("ks"));
        assert_eq!(sec.enclave, None);
        let e = sec.enclave_dir(None).unwrap_err();
        assert!(e.contains("names no enclave"), "{e}");
        for bad in ["/", "/../etc", "/a//b"] {
            let e = sec.enclave_dir(Some(bad)).unwrap_err();
            assert!(e.contains("not a path"), "{bad}: {e}");
        }
        let e = sec.enclave_dir(Some("/lathe1")).unwrap_err();
        assert!(e.contains("cert.pem is missing"), "{e}");
        let lathe = dir.join("ks/enclaves/lathe1");
        std::fs::create_dir_all(&lathe).unwrap();
        for f in ["cert.pem", "key.pem", "permissions.p7s", "governance.p7s"] {
            std::fs::write(lathe.join(f), "x").unwrap();
        }
        assert_eq!(sec.enclave_dir(Some("/lathe1")).unwrap(), lathe);
        let named = cfg.network.with_default_enclave("/cell/robot").unwrap();
        assert_eq!(
            named.security.and_then(|s| s.enclave).as_deref(),
            Some("/cell/robot")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
