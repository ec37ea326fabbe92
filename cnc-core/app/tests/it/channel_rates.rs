//! A channel without a transformation hands its axes the path's own velocity and
//! acceleration; under a transformation the axes take differences of the set-points.

use cnc_app::scenario::file::Scenario;
use cnc_app::scenario::machine::InProcess;

fn run(kinematics: &str, program: &str) -> InProcess {
    let toml = format!(
        "cycle_ms = 1.0\n[[channel]]\nname = \"c\"\n\
         axes = [\"X\", \"Y\", \"Z\", \"A\", \"B\", \"C\"]\n{kinematics}\
         start = [0.0, -60.0, 90.0, 0.0, 60.0, 0.0]\nprogram = \"p.nc\"\n"
    );
    let program = program.to_string();
    let s = Scenario::parse("rates", &toml, |f| {
        Ok((std::path::PathBuf::from(f), program.clone()))
    })
    .unwrap();
    InProcess::new(&s, 0).unwrap()
}

#[test]
fn the_axes_take_the_paths_velocity_and_acceleration_without_a_transformation() {
    let mut run = run("", "%p\nG1 X100 Y-20 F6000\nG2 X120 Y0 I20 J0 F3000\nM30\n");
    let (mut moving, mut not_a_difference) = (0, 0);
    let mut last = 0.0;
    for _ in 0..4000 {
        run.machine.tick(&run.memory);
        let channel = &run.machine.controller().channels()[0];
        let (velocity, acceleration) = channel.set_point_rates().expect("no transformation");
        let (velocity, acceleration) = (velocity[0], acceleration[0]);
        let axis = run.machine.axes().axis(0).unwrap().setpoint();
        assert_eq!((axis.velocity, axis.acceleration), (velocity, acceleration));
        let difference = (axis.position - last) / 0.001;
        last = axis.position;
        moving += usize::from(velocity != 0.0);
        not_a_difference += usize::from((velocity - difference).abs() > 1e-6);
    }
    assert!(moving > 1000, "{moving} ticks moving");
    // While the speed changes, the path's velocity is not the backward difference.
    assert!(not_a_difference > 100, "{not_a_difference}");
}

#[test]
fn under_a_transformation_the_axes_take_differences() {
    let mut run = run(
        "kinematics = { id = 45, preset = \"kr6r900sixx\" }\n",
        "%p\n#TRAFO [45]\nG1 X600 Y10 Z500 F3000\nM30\n",
    );
    let (mut last, mut moving) = (run.machine.axes().axis(0).unwrap().setpoint().position, 0);
    for _ in 0..1500 {
        run.machine.tick(&run.memory);
        let channel = &run.machine.controller().channels()[0];
        assert!(channel.set_point_rates().is_none());
        let axis = run.machine.axes().axis(0).unwrap().setpoint();
        let difference = (axis.position - last) / 0.001;
        last = axis.position;
        assert!((axis.velocity - difference).abs() < 1e-9);
        moving += usize::from(axis.velocity != 0.0);
    }
    assert!(moving > 100, "{moving} ticks moving");
}
