//! The simulated lathe's devices that the PLC drives: electric turret, chuck, door, tailstock,
//! coolant pump, air supply, and the inputs a robot and an operator give. Faults can be
//! injected (stuck turret, lost air, door opened by hand).
//!
//! Outputs and inputs are the standard lathe's wiring (`cnc_msgs::signals::{x, y}`).

use cnc_msgs::signals::{x, y, SignalTable, XImage, YImage};

/// Pockets of the mill's drum magazine (`sim.tool_magazine`), which indexes as the turret
/// does; the standard ladder's magazine rungs count on the same number (D94).
pub const MAGAZINE_POCKETS: u8 = 24;

/// Device timings, s, and the turret's size.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceConfig {
    pub turret_stations: u8,
    /// Time to index one station.
    pub turret_index_time: f64,
    /// Time for the lock to release or engage.
    pub turret_lock_time: f64,
    pub chuck_time: f64,
    pub door_time: f64,
    pub tailstock_time: f64,
    pub coolant_delay: f64,
}

impl Default for DeviceConfig {
    fn default() -> Self {
        DeviceConfig {
            turret_stations: 8,
            turret_index_time: 0.2,
            turret_lock_time: 0.1,
            chuck_time: 0.3,
            door_time: 0.8,
            tailstock_time: 0.5,
            coolant_delay: 0.1,
        }
    }
}

/// A device that travels between two end positions (0 and 1) while one of two valves is on,
/// and stays where it is with both off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Travel {
    pub position: f64,
}

impl Travel {
    fn step(&mut self, to_one: bool, to_zero: bool, time: f64, dt: f64) {
        let rate = if time > 0.0 { dt / time } else { 1.0 };
        match (to_one, to_zero) {
            (true, false) => self.position = (self.position + rate).min(1.0),
            (false, true) => self.position = (self.position - rate).max(0.0),
            _ => {}
        }
    }
    pub fn at_one(&self) -> bool {
        self.position >= 1.0
    }
    pub fn at_zero(&self) -> bool {
        self.position <= 0.0
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Devices {
    cfg: DeviceConfig,
    /// Turret angle in stations from tool 1 (0 … n).
    pub turret: f64,
    /// 1 = locked, 0 = released.
    pub turret_lock: f64,
    /// 1 = clamped.
    pub chuck: Travel,
    /// 1 = closed.
    pub door: Travel,
    /// 1 = forward.
    pub tailstock: Travel,
    coolant_time: f64,
    pub turret_stuck: bool,
    pub air_lost: bool,
    /// Someone holds the door open against the drive.
    pub door_forced_open: bool,
    /// Inputs set from outside: robot signals and panel keys (their X bits).
    pub inputs: XImage,
}

impl Devices {
    /// Power-on: tool 1 locked, chuck clamped, door closed, tailstock back, robot clear.
    pub fn new(cfg: DeviceConfig) -> Self {
        let mut inputs = XImage::default();
        inputs.set(x::ROBOT_CLEAR, true);
        // The panel's override switches stand at 100 % (rapid code 0 is 100 %).
        inputs.bytes[x::FEED_OVERRIDE_SWITCH as usize] = 100;
        inputs.bytes[x::SPINDLE_OVERRIDE_SWITCH as usize] = 100;
        Devices {
            cfg,
            turret: 0.0,
            turret_lock: 1.0,
            chuck: Travel { position: 1.0 },
            door: Travel { position: 1.0 },
            tailstock: Travel { position: 0.0 },
            coolant_time: 0.0,
            turret_stuck: false,
            air_lost: false,
            door_forced_open: false,
            inputs,
        }
    }

    /// The station the turret stands at (1-based), if its sensor sees it: within a quarter
    /// of a station, where the locking pin still pulls it into place.
    pub fn turret_station(&self) -> Option<u8> {
        let n = f64::from(self.cfg.turret_stations);
        let p = self.turret.rem_euclid(n);
        let nearest = p.round();
        ((p - nearest).abs() < 0.25).then(|| (nearest.rem_euclid(n)) as u8 + 1)
    }

    pub fn step(&mut self, yi: &YImage, dt: f64) {
        let c = self.cfg.clone();
        // Turret: the motor turns only with the lock released; with the unlock valve off the
        // lock engages if a station is under the pin.
        let unlock = yi.get(y::TURRET_UNLOCK) && !self.air_lost;
        let lock_rate = if c.turret_lock_time > 0.0 {
            dt / c.turret_lock_time
        } else {
            1.0
        };
        if unlock {
            self.turret_lock = (self.turret_lock - lock_rate).max(0.0);
        } else if self.turret_station().is_some() {
            self.turret_lock = (self.turret_lock + lock_rate).min(1.0);
            if self.turret_lock >= 1.0 {
                self.turret = self.turret.round();
            }
        }
        let (cw, ccw) = (yi.get(y::TURRET_CW), yi.get(y::TURRET_CCW));
        if self.turret_lock <= 0.0 && cw != ccw && !self.turret_stuck {
            let v = if cw { 1.0 } else { -1.0 } / c.turret_index_time.max(1e-3);
            self.turret = (self.turret + v * dt).rem_euclid(f64::from(c.turret_stations));
        }
        let air = !self.air_lost;
        self.chuck.step(
            air && yi.get(y::CHUCK_CLAMP),
            air && yi.get(y::CHUCK_UNCLAMP),
            c.chuck_time,
            dt,
        );
        self.door.step(
            yi.get(y::DOOR_CLOSE) && !self.door_forced_open,
            yi.get(y::DOOR_OPEN) || self.door_forced_open,
            c.door_time,
            dt,
        );
        if self.door_forced_open {
            self.door.position = self.door.position.min(0.5);
        }
        self.tailstock.step(
            yi.get(y::TAILSTOCK_FORWARD),
            yi.get(y::TAILSTOCK_BACK),
            c.tailstock_time,
            dt,
        );
        self.coolant_time = if yi.get(y::COOLANT) {
            self.coolant_time + dt
        } else {
            0.0
        };
    }

    /// Writes the devices' sensors and the outside inputs into `xi`.
    pub fn sensors(&self, xi: &mut XImage) {
        for (b, v) in xi.bytes.iter_mut().zip(self.inputs.bytes) {
            *b |= v;
        }
        let station = self.turret_station();
        for (k, bit) in x::TOOL
            .iter()
            .enumerate()
            .take(self.cfg.turret_stations.into())
        {
            xi.set(*bit, station == Some(k as u8 + 1));
        }
        // The station (magazine pocket) as a binary code, 0 between stations.
        xi.bytes[usize::from(x::STATION_CODE)] = station.unwrap_or(0);
        xi.set(x::TURRET_LOCKED, self.turret_lock >= 1.0);
        xi.set(x::CHUCK_CLAMPED, self.chuck.at_one());
        xi.set(x::CHUCK_UNCLAMPED, self.chuck.at_zero());
        xi.set(x::DOOR_CLOSED, self.door.at_one());
        xi.set(x::DOOR_OPEN, self.door.at_zero());
        xi.set(x::TAILSTOCK_FORWARD, self.tailstock.at_one());
        xi.set(x::TAILSTOCK_BACK, self.tailstock.at_zero());
        xi.set(x::AIR_OK, !self.air_lost);
        xi.set(
            x::COOLANT_PRESSURE,
            self.coolant_time >= self.cfg.coolant_delay && self.coolant_time > 0.0,
        );
        xi.set(x::LUBE_OK, true);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(d: &mut Devices, yi: &YImage, seconds: f64) {
        for _ in 0..(seconds / 0.004).round() as usize {
            d.step(yi, 0.004);
        }
    }

    #[test]
    fn turret_turns_only_unlocked_and_locks_on_a_station() {
        let mut d = Devices::new(DeviceConfig::default());
        let mut yi = YImage::default();
        yi.set(y::TURRET_CCW, true);
        run(&mut d, &yi, 0.5);
        assert_eq!(
            d.turret_station(),
            Some(1),
            "locked: the motor cannot turn it"
        );
        yi.set(y::TURRET_UNLOCK, true);
        run(&mut d, &yi, 0.1 + 0.4);
        // 0.4 s at 0.2 s per station backwards from 1: station 7.
        assert_eq!(d.turret_station(), Some(7));
        yi.set(y::TURRET_CCW, false);
        yi.set(y::TURRET_UNLOCK, false);
        run(&mut d, &yi, 0.2);
        let mut xi = XImage::default();
        d.sensors(&mut xi);
        assert!(xi.get(x::TOOL[6]) && xi.get(x::TURRET_LOCKED));
        d.turret_stuck = true;
        yi.set(y::TURRET_UNLOCK, true);
        yi.set(y::TURRET_CW, true);
        run(&mut d, &yi, 1.0);
        assert_eq!(d.turret_station(), Some(7), "stuck");
    }

    #[test]
    fn chuck_door_and_air() {
        let mut d = Devices::new(DeviceConfig::default());
        let mut yi = YImage::default();
        yi.set(y::CHUCK_UNCLAMP, true);
        yi.set(y::DOOR_OPEN, true);
        run(&mut d, &yi, 0.2);
        let mut xi = XImage::default();
        d.sensors(&mut xi);
        assert!(!xi.get(x::CHUCK_CLAMPED) && !xi.get(x::CHUCK_UNCLAMPED));
        run(&mut d, &yi, 1.0);
        let mut xi = XImage::default();
        d.sensors(&mut xi);
        assert!(xi.get(x::CHUCK_UNCLAMPED) && xi.get(x::DOOR_OPEN) && xi.get(x::ROBOT_CLEAR));
        d.air_lost = true;
        yi = YImage::default();
        yi.set(y::CHUCK_CLAMP, true);
        run(&mut d, &yi, 1.0);
        let mut xi = XImage::default();
        d.sensors(&mut xi);
        assert!(
            !xi.get(x::CHUCK_CLAMPED) && !xi.get(x::AIR_OK),
            "no air, no clamping"
        );
    }
}
