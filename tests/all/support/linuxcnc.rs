//! The real LinuxCNC as a test oracle: a headless simulation configuration (Debian's
//! `linuxcnc-uspace`, HAL's `basic_sim.tcl` with simulated joints, without its velocity
//! signals so that a test may load `hypot` itself) with a kinematics module and
//! pins of our choosing; a Python driver in place of the GUI (`[DISPLAY] DISPLAY`) resets the
//! e-stop, switches the machine on, homes it, sends each block as MDI (or sets a HAL pin, for a
//! `setp` line), waits until the joints stand still, and writes `stat.joint_actual_position` and
//! the probe's latched position.
//!
//! Without LinuxCNC the tests say so and pass, except in CI (`CI` set), where they fail and say
//! how to install it. One LinuxCNC runs at a time (HAL's shared memory is one per machine): a
//! lock file in the system's temporary directory serialises the runs of every test process.
//! Running it needs root (LinuxCNC's realtime helper is set-uid root): as root, `RTAPI_UID`
//! names the unprivileged user it drops to, and `RTAPI_FIFO_PATH` puts its socket in the run's
//! own directory.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long one LinuxCNC run may take before it is killed.
const TIMEOUT: Duration = Duration::from_secs(90);

/// The Python with LinuxCNC's module (Debian's, not a virtual environment's).
const PYTHON: &str = "/usr/bin/python3";

/// A LinuxCNC installation.
pub struct LinuxCnc {
    linuxcnc: PathBuf,
}

/// A machine configuration for a run.
pub struct Config<'a> {
    /// `[KINS] KINEMATICS`: `xyzac-trt-kins`, `xyzbc-trt-kins` or `trivkins coordinates=XYZAC`.
    pub kinematics: &'a str,
    /// `[TRAJ] COORDINATES`, five letters (joints 0–4).
    pub coordinates: &'a str,
    /// HAL commands run after the simulation is loaded (`setp` lines).
    pub hal: &'a str,
}

fn usable() -> Result<PathBuf, String> {
    let linuxcnc = super::on_path("linuxcnc".as_ref()).ok_or("no `linuxcnc` on PATH")?;
    let module = Command::new(PYTHON)
        .args(["-c", "import linuxcnc"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| format!("{PYTHON}: {e}"))?;
    if !module.success() {
        return Err(format!("{PYTHON} has no `linuxcnc` module"));
    }
    Ok(linuxcnc)
}

/// LinuxCNC for the test `test`, or `None` (said on stderr) where it is not installed; in CI
/// a missing LinuxCNC fails the test.
pub fn for_test(test: &str) -> Option<LinuxCnc> {
    match usable() {
        Ok(linuxcnc) => Some(LinuxCnc { linuxcnc }),
        Err(why) if super::required_in_ci() => panic!(
            "{test}: LinuxCNC is needed and CI is set: {why}; install it (Debian: `apt-get install \
             --no-install-recommends linuxcnc-uspace`)"
        ),
        Err(why) => {
            let _ = writeln!(std::io::stderr(), "{test}: skipped, {why}");
            None
        }
    }
}

/// The driver: the GUI LinuxCNC starts (`DISPLAY`), run in the configuration's directory.
const DRIVER: &str = r#"#!/usr/bin/python3
import linuxcnc, hal, time, sys
# LinuxCNC drops a display's output: the harness reads this file when the run fails.
sys.stderr = open("driver.err", "w", buffering=1)
s = linuxcnc.stat(); c = linuxcnc.command(); e = linuxcnc.error_channel()
# hal.set_p needs a component of this process.
me = hal.component("rtest-driver"); me.ready()
def check(after):
    err = e.poll()
    if err and err[0] in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
        sys.exit("LinuxCNC error after " + after + ": " + err[1])
def wait(cond, what, t=20):
    end = time.time() + t
    while time.time() < end:
        s.poll()
        if cond(): return
        time.sleep(0.002)
    sys.exit("timeout waiting for " + what)
wait(lambda: True, "status")
c.state(linuxcnc.STATE_ESTOP_RESET); c.state(linuxcnc.STATE_ON)
wait(lambda: s.task_state == linuxcnc.STATE_ON, "machine on")
c.mode(linuxcnc.MODE_MANUAL); c.wait_complete()
c.teleop_enable(False); c.wait_complete()
c.home(-1)
wait(lambda: all(s.homed[i] for i in range(5)), "homing")
c.mode(linuxcnc.MODE_MDI); c.wait_complete()
out = open("joints.txt", "w")
probed = open("probed.txt", "w")
for line in open("blocks.txt"):
    if line.startswith("setp "):
        _, pin, value = line.split()
        hal.set_p(pin, value)
        time.sleep(0.01)
    else:
        c.mdi(line.strip())
        # What c.wait_complete(60) waits for (the command echoed, then done or failed), polled
        # every 2 ms instead of every 10 ms.
        serial = c.serial
        wait(lambda: s.echo_serial_number - serial > 0 or (s.echo_serial_number == serial
             and s.state in (linuxcnc.RCS_DONE, linuxcnc.RCS_ERROR)), "MDI: " + line.strip(), 60)
        wait(lambda: s.interp_state == linuxcnc.INTERP_IDLE, "the interpreter", 60)
        check(line)
    last, still = None, 0
    while still < 5:
        time.sleep(0.003); s.poll()
        now = tuple(s.joint_actual_position[:5])
        still = still + 1 if now == last else 0
        last = now
    out.write(" ".join(repr(v) for v in last) + "\n")
    probed.write(" ".join(repr(v) for v in s.probed_position[:3]) + " " + str(int(s.probe_tripped)) + "\n")
out.close()
probed.close()
open("done", "w").write("ok\n")
"#;

/// The INI of a run.
fn ini(config: &Config) -> String {
    let mut t = format!(
        "[EMC]\nVERSION = 1.1\nMACHINE = rtest-oracle\n[DISPLAY]\nDISPLAY = ./driver.py\n\
         [RS274NGC]\nPARAMETER_FILE = sim.var\n[KINS]\nKINEMATICS = {}\nJOINTS = 5\n\
         [HAL]\nHALFILE = LIB:basic_sim.tcl -no_make_ddts -no_use_hal_manualtoolchange -no_sim_spindle\n\
         HALFILE = pins.hal\n[TRAJ]\nCOORDINATES = {}\nLINEAR_UNITS = mm\nANGULAR_UNITS = deg\n\
         MAX_LINEAR_VELOCITY = 100000\nDEFAULT_LINEAR_VELOCITY = 100000\n\
         MAX_LINEAR_ACCELERATION = 10000000\nDEFAULT_LINEAR_ACCELERATION = 10000000\n\
         [EMCMOT]\nEMCMOT = motmod\nSERVO_PERIOD = 1000000\nCOMM_TIMEOUT = 1\n\
         [TASK]\nTASK = milltask\nCYCLE_TIME = 0.001\n[EMCIO]\nEMCIO = io\nCYCLE_TIME = 0.100\n\
         TOOL_TABLE = sim.tbl\n",
        config.kinematics, config.coordinates
    );
    let limits = "MIN_LIMIT = -100000\nMAX_LIMIT = 100000\nMAX_VELOCITY = 100000\nMAX_ACCELERATION = 10000000\n";
    for (j, letter) in config.coordinates.chars().enumerate() {
        t += &format!("[AXIS_{letter}]\n{limits}");
        let kind = if "ABC".contains(letter) {
            "ANGULAR"
        } else {
            "LINEAR"
        };
        t += &format!(
            "[JOINT_{j}]\nTYPE = {kind}\nHOME = 0\nHOME_SEARCH_VEL = 0\nHOME_SEQUENCE = 0\n{limits}"
        );
    }
    t
}

impl LinuxCnc {
    /// Runs `blocks` (MDI lines, mm and degrees) on a simulated machine of `config` in `dir`
    /// and returns the joint positions after each (mm and degrees, joints 0–4).
    pub fn run(
        &self,
        dir: &Path,
        config: &Config,
        blocks: &[String],
    ) -> Result<Vec<[f64; 5]>, String> {
        let lock_path = std::env::temp_dir().join("rtest-linuxcnc.lock");
        let lock = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
            .map_err(|e| format!("{}: {e}", lock_path.display()))?;
        lock.lock()
            .map_err(|e| format!("{}: {e}", lock_path.display()))?;
        let result = self.run_locked(dir, config, blocks);
        let _ = lock.unlock();
        result
    }

    fn run_locked(
        &self,
        dir: &Path,
        config: &Config,
        blocks: &[String],
    ) -> Result<Vec<[f64; 5]>, String> {
        let write = |name: &str, text: &str| {
            std::fs::write(dir.join(name), text).map_err(|e| format!("{name}: {e}"))
        };
        write("sim.ini", &ini(config))?;
        write("pins.hal", config.hal)?;
        write("sim.tbl", "T1 P1 Z0 ;\n")?;
        write("blocks.txt", &(blocks.join("\n") + "\n"))?;
        write("driver.py", DRIVER)?;
        let fifo = dir.join("fifo");
        std::fs::create_dir_all(&fifo).map_err(|e| e.to_string())?;
        use std::os::unix::fs::PermissionsExt;
        for d in [dir, fifo.as_path()] {
            std::fs::set_permissions(d, std::fs::Permissions::from_mode(0o1777))
                .map_err(|e| e.to_string())?;
        }
        std::fs::set_permissions(
            dir.join("driver.py"),
            std::fs::Permissions::from_mode(0o755),
        )
        .map_err(|e| e.to_string())?;
        let log = std::fs::File::create(dir.join("linuxcnc.log")).map_err(|e| e.to_string())?;
        let started = Instant::now();
        let mut child = Command::new(&self.linuxcnc)
            .arg("sim.ini")
            .current_dir(dir)
            .env("RTAPI_UID", "65534")
            .env("RTAPI_FIFO_PATH", fifo.join("rtapi_fifo"))
            .stdin(Stdio::null())
            .stdout(log.try_clone().map_err(|e| e.to_string())?)
            .stderr(log)
            .spawn()
            .map_err(|e| format!("{}: {e}", self.linuxcnc.display()))?;
        let status = loop {
            if let Some(s) = child.try_wait().map_err(|e| e.to_string())? {
                break s;
            }
            if started.elapsed() > TIMEOUT {
                let _ = child.kill();
                let _ = child.wait();
                let _ = Command::new("pkill")
                    .args(["-9", "-f", "rtapi_app"])
                    .status();
                return Err(format!(
                    "LinuxCNC did not finish in {} s; its log: {}",
                    TIMEOUT.as_secs(),
                    dir.join("linuxcnc.log").display()
                ));
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        let mut log_text = std::fs::read_to_string(dir.join("linuxcnc.log")).unwrap_or_default();
        // Without a terminal LinuxCNC writes its messages to a debug file, and copies it to
        // `$HOME/linuxcnc_debug.txt` when it fails: its lines without the shell trace.
        if let Some(home) = std::env::var_os("HOME") {
            let debug = Path::new(&home).join("linuxcnc_debug.txt");
            if let Ok(text) = std::fs::read_to_string(&debug) {
                let lines: Vec<&str> = text
                    .lines()
                    .filter(|l| !l.starts_with('+') && !l.trim().is_empty())
                    .collect();
                let tail = &lines[lines.len().saturating_sub(30)..];
                log_text += &format!("\n{} (last lines):\n{}", debug.display(), tail.join("\n"));
            }
        }
        if let Ok(text) = std::fs::read_to_string(dir.join("driver.err"))
            && !text.trim().is_empty()
        {
            log_text += &format!("\nthe driver's errors:\n{text}");
        }
        if !dir.join("done").exists() {
            return Err(format!(
                "LinuxCNC ({status}) did not run every block; its log:\n{log_text}"
            ));
        }
        let text = std::fs::read_to_string(dir.join("joints.txt")).map_err(|e| e.to_string())?;
        let rows: Vec<[f64; 5]> = text
            .lines()
            .map(|l| {
                let v: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2], v[3], v[4]]
            })
            .collect();
        if rows.len() != blocks.len() {
            return Err(format!(
                "{} joint rows for {} blocks",
                rows.len(),
                blocks.len()
            ));
        }
        eprintln!(
            "LinuxCNC ({}): {} blocks in {:.1} s",
            config.kinematics,
            blocks.len(),
            started.elapsed().as_secs_f64()
        );
        Ok(rows)
    }
}

/// One block's result: LinuxCNC's last probed position (`stat.probed_position`, world
/// coordinates, mm) and whether the probe tripped.
pub struct BlockResult {
    /// The position latched at the last probe trip (X, Y, Z; mm).
    pub probed: [f64; 3],
    /// `stat.probe_tripped` after the block.
    pub tripped: bool,
}

impl LinuxCnc {
    /// [`LinuxCnc::run`], with the probe's latched positions: a block may also be a
    /// `setp PIN VALUE` line, which sets a HAL pin (a probing target's centre, say) between
    /// two blocks.
    pub fn run_probing(
        &self,
        dir: &Path,
        config: &Config,
        blocks: &[String],
    ) -> Result<Vec<BlockResult>, String> {
        self.run(dir, config, blocks)?;
        let text = std::fs::read_to_string(dir.join("probed.txt")).map_err(|e| e.to_string())?;
        let probed: Vec<(Vec<f64>, bool)> = text
            .lines()
            .map(|l| {
                let v: Vec<&str> = l.split(' ').collect();
                (
                    v[..3].iter().map(|x| x.parse().unwrap()).collect(),
                    v[3] == "1",
                )
            })
            .collect();
        Ok(probed
            .into_iter()
            .map(|(p, tripped)| BlockResult {
                probed: [p[0], p[1], p[2]],
                tripped,
            })
            .collect())
    }
}

/// A G-code number: the shortest decimal that reads back to the same `f64`, without an
/// exponent (Rust's `Display` of `f64`).
pub fn number(x: f64) -> String {
    format!("{}", x + 0.0)
}

/// The HAL of a calibration sphere of radius `radius` (mm; the sphere's plus the tip's) about
/// `centre` (joints 0–2, mm), made of stock components: `sum2` for the tip's offsets from the
/// centre (`sphere-dx`, `sphere-dy`, `sphere-dz`: `in0` the joint, `offset` minus the centre),
/// `hypot` for their length, `wcomp` for "inside", which drives `motion.probe-input`. The
/// simulation must be loaded without its own `hypot` (`basic_sim.tcl -no_make_ddts`, as
/// [`Config`]'s INI does). [`sphere_centre_setp`] moves it between blocks.
pub fn sphere_hal(centre: [f64; 3], radius: f64) -> String {
    let mut h = String::from(
        "loadrt sum2 names=sphere-dx,sphere-dy,sphere-dz\nloadrt hypot names=sphere-distance\n\
         loadrt wcomp names=sphere-inside\n\
         addf sphere-dx servo-thread\naddf sphere-dy servo-thread\naddf sphere-dz servo-thread\n\
         addf sphere-distance servo-thread\naddf sphere-inside servo-thread\n",
    );
    for (j, (c, d)) in centre.iter().zip(["dx", "dy", "dz"]).enumerate() {
        h += &format!(
            "net J{j}:pos-fb => sphere-{d}.in0\nsetp sphere-{d}.gain0 1\nsetp sphere-{d}.gain1 0\nsetp sphere-{d}.offset {}\nnet sphere-{d} sphere-{d}.out => sphere-distance.in{j}\n",
            number(-c)
        );
    }
    h += &format!(
        "net sphere-distance sphere-distance.out => sphere-inside.in\nsetp sphere-inside.min -1\nsetp sphere-inside.max {}\nnet sphere-probe sphere-inside.out => motion.probe-input\n",
        number(radius)
    );
    h
}

/// The `setp` lines (blocks of [`LinuxCnc::run_probing`]) that move the sphere of
/// [`sphere_hal`] to `centre` (joints 0–2, mm).
pub fn sphere_centre_setp(centre: [f64; 3]) -> Vec<String> {
    centre
        .iter()
        .zip(["dx", "dy", "dz"])
        .map(|(c, d)| format!("setp sphere-{d}.offset {}", number(-c)))
        .collect()
}
