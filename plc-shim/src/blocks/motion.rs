//! PLCopen-style motion blocks for the PLC program: MC_Power, MC_Reset, MC_MoveAbsolute,
//! MC_MoveRelative, MC_MoveVelocity, MC_MoveSuperimposed, MC_Halt and MC_Stop. Each is called once per PLC cycle
//! with its axis (the index in `gpAx`). On a rising Execute edge a block sends its command
//! over the acyclic service without waiting; it stays Busy until the CNC answers with a
//! command id, then follows that id in the axis's command book in the image (no further
//! calls). Outputs follow PLCopen: Busy while the command runs; then exactly one of Done,
//! CommandAborted, Error (with ErrorID), held while Execute stays TRUE, or for one cycle if
//! Execute already fell.

use super::plain;
use crate::kernel::{send, Accept, Kernel, Outputs, Step, Waited};
use crate::runtime::PlcIo;
use crate::timeline::registry::{input, BlockSpec, InputSpec, Kind, Target, TimelineBlock, Value};
use hli::calls::axis::{AxisCommandCall, AxisCommandReply};
use hli::command_book::{view_command, CommandView};
use hli::enums::axis_status;
use hli::layout::{HliAxis, HliAxisCommandState, HliAxisDriveState, HliAxisLrState};
use hli::PlaceExt;
use hli_transport::rpc::PendingCall;

/// The block kernel as the motion blocks use it: the accepted command's id is followed in
/// the axis's command book.
#[derive(Debug, Default)]
pub struct CommandCore {
    kernel: Kernel<PendingCall<AxisCommandCall>, u32>,
    /// The command runs beside the one owning the axis (MC_MoveSuperimposed): busy while the
    /// axis shows it as its superimposed move.
    beside: bool,
}

fn accept(reply: AxisCommandReply) -> Accept<u32, ()> {
    if reply.error_id != 0 {
        Accept::Failed(reply.error_id, ())
    } else {
        Accept::Follow(reply.command_id, Outputs::busy())
    }
}

/// The outputs the command book shows for command `id` of `axis`; `finished_when_reached`:
/// Done (and the outputs hold) once the goal is reached although the command keeps the axis.
/// `beside`: the command runs beside the owning one (see [`CommandCore`]).
fn follow(
    io: &PlcIo<'_>,
    axis: u32,
    id: u32,
    finished_when_reached: bool,
    beside: bool,
) -> Step<()> {
    let Ok(place) = io.view.axis(axis as usize) else {
        return Step::Ended(Outputs::failed(hli::calls::ErrorCode::InvalidTarget.raw()));
    };
    // The superimposed id first: the CNC writes the book before it, so a move that ends
    // between the two reads is then found in the book as Done, never missed by both.
    let running_beside = place
        .field::<u32>(
            core::mem::offset_of!(HliAxis, drive_state)
                + core::mem::offset_of!(HliAxisDriveState, superimposed_id_r),
        )
        .read();
    let book: HliAxisCommandState = place
        .field::<HliAxisCommandState>(core::mem::offset_of!(HliAxis, command_state))
        .read();
    if beside && id != 0 && running_beside == id {
        return Step::Running(Outputs {
            busy: true,
            active: true,
            ..Outputs::default()
        });
    }
    match view_command(&book, id) {
        CommandView::Busy(reached) if reached && finished_when_reached => Step::Ended(Outputs {
            done: true,
            active: true,
            ..Outputs::default()
        }),
        CommandView::Busy(reached) => Step::Running(Outputs {
            busy: true,
            active: true,
            in_velocity: reached,
            ..Outputs::default()
        }),
        CommandView::Done => Step::Ended(Outputs::done(())),
        CommandView::Aborted | CommandView::Unknown => Step::Ended(Outputs::aborted()),
        CommandView::Error(code) => Step::Ended(Outputs::failed(code)),
    }
}

impl CommandCore {
    /// A core for a command that runs beside the one owning the axis (MC_MoveSuperimposed).
    pub fn beside() -> Self {
        Self {
            beside: true,
            ..Self::default()
        }
    }

    /// One cycle: `call` is sent on a rising edge of `execute`. Returns the block's outputs.
    /// `finished_when_reached`: the command counts as Done once its goal is reached although it
    /// keeps the axis (MC_Stop).
    pub fn cycle(
        &mut self,
        io: &mut PlcIo<'_>,
        axis: u32,
        execute: bool,
        call: impl FnOnce() -> AxisCommandCall,
        finished_when_reached: bool,
    ) -> Outputs {
        let beside = self.beside;
        self.kernel.cycle(
            io,
            execute,
            |io| send(io, axis, &call()),
            accept,
            |id, io, _: Waited| follow(io, axis, *id, finished_when_reached, beside),
        )
    }

    /// Whether Execute fell in the last cycle.
    pub fn fell(&self) -> bool {
        self.kernel.fell()
    }
}

/// MC_Power: enables the axis while `enable` is TRUE. A refused level is sent again once the
/// axis reports no error and stands (the causes of a refusal).
#[derive(Debug, Default)]
pub struct McPower {
    /// Input: enable the axis.
    pub enable: bool,
    /// Output: the axis reports enabled.
    pub status: bool,
    /// Output: the last enable/disable was refused.
    pub error: bool,
    /// Output: why.
    pub error_id: u32,
    core: CommandCore,
    sent: Option<bool>,
}

impl McPower {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let state = io.view.axis_state(axis as usize).ok();
        let refusal_gone = state.is_some_and(|s: HliAxisLrState| {
            s.error_id_r == 0 && s.status_r & axis_status::MOVING == 0
        });
        if self.sent != Some(self.enable) || (self.error && refusal_gone) {
            // A new level: send it (the core sends on its rising edge).
            self.core = CommandCore::default();
            self.sent = Some(self.enable);
        }
        let enable = self.enable;
        let out = self
            .core
            .cycle(io, axis, true, || AxisCommandCall::power(enable), false);
        self.error = out.error;
        self.error_id = out.error_id;
        self.status = state.is_some_and(|s| s.status_r & axis_status::ENABLED != 0);
    }
}

/// A motion block whose inputs are numbers: the block, its call (`$build` from the inputs;
/// `reached_is_done` as [`CommandCore::cycle`] takes it), its `TimelineBlock` and its
/// `INPUTS`, each input by its field's name.
macro_rules! execute_block {
    // A move: its own inputs, then the limits `limits()` gives in the call's order.
    ($(#[doc = $doc:literal])* $name:ident { $($(#[doc = $fdoc:literal])* $field:ident),* } + limits => |$s:ident| $build:expr, reached_is_done = $reached:expr) => {
        execute_block! {
            $(#[doc = $doc])*
            $name {
                $($(#[doc = $fdoc])* $field,)*
                /// Input: velocity limit.
                velocity,
                /// Input: acceleration limit.
                acceleration,
                /// Input: deceleration limit.
                deceleration,
                /// Input: jerk limit.
                jerk
            } => |$s| $build, reached_is_done = $reached
        }

        impl $name {
            /// Velocity, acceleration, deceleration and jerk limit.
            fn limits(&self) -> [f64; 4] {
                [self.velocity, self.acceleration, self.deceleration, self.jerk]
            }
        }
    };
    ($(#[doc = $doc:literal])* $name:ident { $($(#[doc = $fdoc:literal])* $field:ident),* } => |$s:ident| $build:expr, reached_is_done = $reached:expr) => {
        $(#[doc = $doc])*
        #[derive(Debug, Default)]
        pub struct $name {
            /// Input: a rising edge starts the command.
            pub execute: bool,
            $($(#[doc = $fdoc])* pub $field: f64,)*
            /// Outputs of the last call.
            pub out: Outputs,
            core: CommandCore,
        }

        impl $name {
            /// The inputs a timeline call sets: its fields but Execute, numbers all.
            const INPUTS: &'static [InputSpec] = &[$(input(stringify!($field), Kind::Real)),*];

            /// One cycle for `axis`.
            pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
                let $s = &*self;
                let call = $build;
                self.out = self.core.cycle(io, axis, self.execute, || call, $reached);
            }
        }

        impl TimelineBlock for $name {
            fn set(&mut self, key: &str, value: &Value) {
                let _ = (key, value);
                $(if let (stringify!($field), Value::Real(v)) = (key, value) {
                    self.$field = *v;
                })*
            }
            execute_cycle!(with_axis, plain);
        }
    };
}

execute_block! {
    /// MC_Reset: clears the axis error once its cause is gone.
    McReset {} => |_s| AxisCommandCall::reset(), reached_is_done = false
}

execute_block! {
    /// MC_MoveAbsolute: moves to `position`.
    McMoveAbsolute {
        /// Input: target position.
        position
    } + limits => |s| AxisCommandCall::move_absolute(s.position, s.limits()),
    reached_is_done = false
}

execute_block! {
    /// MC_MoveRelative: moves by `distance` from the set position.
    McMoveRelative {
        /// Input: distance.
        distance
    } + limits => |s| AxisCommandCall::move_relative(s.distance, s.limits()),
    reached_is_done = false
}

/// MC_MoveVelocity: runs endlessly at `velocity` in `direction`; InVelocity once reached.
#[derive(Debug, Default)]
pub struct McMoveVelocity {
    /// Input: a rising edge starts the command.
    pub execute: bool,
    /// Input: 1 positive, -1 negative.
    pub direction: i32,
    /// Input: velocity (> 0).
    pub velocity: f64,
    /// Input: acceleration limit.
    pub acceleration: f64,
    /// Input: deceleration limit.
    pub deceleration: f64,
    /// Input: jerk limit.
    pub jerk: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CommandCore,
}

impl McMoveVelocity {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = AxisCommandCall::move_velocity(
            self.direction,
            [
                self.velocity,
                self.acceleration,
                self.deceleration,
                self.jerk,
            ],
        );
        self.out = self.core.cycle(io, axis, self.execute, || call, false);
    }
}

execute_block! {
    /// MC_Halt: brakes to standstill; another move may take over.
    McHalt {
        /// Input: deceleration.
        deceleration,
        /// Input: jerk.
        jerk
    } => |s| AxisCommandCall::halt(s.deceleration, s.jerk), reached_is_done = false
}

execute_block! {
    /// MC_SetPosition: at standstill the axis's encoder counts from `position` (its counter
    /// is set through the encoder's register); nothing moves. Done once the encoder answered.
    McSetPosition {
        /// Input: the position the axis stands at from now on.
        position
    } => |s| AxisCommandCall::set_position(s.position), reached_is_done = true
}

/// MC_MoveSuperimposed: adds `distance` to the motion of a cam or gear slave, at most
/// `velocity_diff` faster or slower than the coupled motion, beside the command that owns the
/// axis. CommandAborted when a new MC_MoveSuperimposed, the coupling's end or an axis error
/// ends it; a free axis refuses it (0x4235).
#[derive(Debug)]
pub struct McMoveSuperimposed {
    /// Input: a rising edge starts the move.
    pub execute: bool,
    /// Input: the distance added.
    pub distance: f64,
    /// Input: the largest velocity difference to the coupled motion (> 0).
    pub velocity_diff: f64,
    /// Input: acceleration limit.
    pub acceleration: f64,
    /// Input: deceleration limit.
    pub deceleration: f64,
    /// Input: jerk limit.
    pub jerk: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CommandCore,
}

impl Default for McMoveSuperimposed {
    fn default() -> Self {
        Self {
            execute: false,
            distance: 0.0,
            velocity_diff: 0.0,
            acceleration: 0.0,
            deceleration: 0.0,
            jerk: 0.0,
            out: Outputs::default(),
            core: CommandCore::beside(),
        }
    }
}

impl McMoveSuperimposed {
    /// The inputs a timeline call sets.
    const INPUTS: &'static [InputSpec] = &[
        input("distance", Kind::Real),
        input("velocity_diff", Kind::Real),
        ACCELERATION,
        DECELERATION,
        JERK,
    ];

    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = AxisCommandCall::move_superimposed(
            self.distance,
            [
                self.velocity_diff,
                self.acceleration,
                self.deceleration,
                self.jerk,
            ],
        );
        self.out = self.core.cycle(io, axis, self.execute, || call, false);
    }
}

impl TimelineBlock for McMoveSuperimposed {
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("distance", Value::Real(v)) => self.distance = *v,
            ("velocity_diff", Value::Real(v)) => self.velocity_diff = *v,
            ("acceleration", Value::Real(v)) => self.acceleration = *v,
            ("deceleration", Value::Real(v)) => self.deceleration = *v,
            ("jerk", Value::Real(v)) => self.jerk = *v,
            _ => {}
        }
    }
    execute_cycle!(with_axis, plain);
}

/// MC_Stop: brakes to standstill and keeps the axis locked while Execute stays TRUE.
#[derive(Debug, Default)]
pub struct McStop {
    /// Input: a rising edge stops; the falling edge releases the lock.
    pub execute: bool,
    /// Input: deceleration.
    pub deceleration: f64,
    /// Input: jerk.
    pub jerk: f64,
    /// Outputs of the last call.
    pub out: Outputs,
    core: CommandCore,
    release: Option<PendingCall<AxisCommandCall>>,
    release_due: bool,
}

impl McStop {
    /// One cycle for `axis`.
    pub fn call(&mut self, io: &mut PlcIo<'_>, axis: u32) {
        let call = AxisCommandCall::stop(self.deceleration, self.jerk);
        self.out = self.core.cycle(io, axis, self.execute, || call, true);
        self.release_due |= self.core.fell();
        // The release is sent until the CNC has taken it: a lost one would lock the axis.
        if self.release_due && self.release.is_none() {
            self.release = io
                .acyclic
                .start(axis, &AxisCommandCall::stop_release())
                .ok();
        }
        if let Some(result) = self.release.as_ref().and_then(PendingCall::poll) {
            self.release = None;
            if result.is_ok_and(|reply| reply.error_id == 0) {
                self.release_due = false;
            }
        }
    }
}

impl TimelineBlock for McPower {
    fn set(&mut self, key: &str, value: &Value) {
        if let ("enable", Value::Bool(v)) = (key, value) {
            self.enable = *v;
        }
    }
    fn execute(&mut self) -> Option<&mut bool> {
        None // the level of `enable` is the command
    }
    fn cycle(&mut self, io: &mut PlcIo<'_>, axis: u32) -> (Outputs, bool) {
        self.call(io, axis);
        let out = Outputs {
            error: self.error,
            error_id: self.error_id,
            ..Outputs::default()
        };
        (out, self.status)
    }
}

impl TimelineBlock for McMoveVelocity {
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("direction", Value::Int(d)) => self.direction = *d as i32,
            ("velocity", Value::Real(v)) => self.velocity = *v,
            ("acceleration", Value::Real(v)) => self.acceleration = *v,
            ("deceleration", Value::Real(v)) => self.deceleration = *v,
            ("jerk", Value::Real(v)) => self.jerk = *v,
            _ => {}
        }
    }
    execute_cycle!(with_axis, plain);
}

impl TimelineBlock for McStop {
    fn set(&mut self, key: &str, value: &Value) {
        match (key, value) {
            ("deceleration", Value::Real(v)) => self.deceleration = *v,
            ("jerk", Value::Real(v)) => self.jerk = *v,
            _ => {}
        }
    }
    execute_cycle!(with_axis, plain);
}

/// The limits of a move: velocity, acceleration, deceleration, jerk.
const VELOCITY: InputSpec = input("velocity", Kind::Real);
const ACCELERATION: InputSpec = input("acceleration", Kind::Real);
const DECELERATION: InputSpec = input("deceleration", Kind::Real);
const JERK: InputSpec = input("jerk", Kind::Real);

/// The motion blocks a timeline calls.
pub const TIMELINE: &[BlockSpec] = &[
    BlockSpec {
        name: "MC_Power",
        target: Target::Axis,
        execute: false,
        inputs: &[input("enable", Kind::Bool)],
        make: |_| Box::<McPower>::default(),
        style: crate::timeline::registry::StStyle::PlcOpen,
    },
    BlockSpec::on_axis("MC_Reset", McReset::INPUTS, |_| Box::<McReset>::default()),
    BlockSpec::on_axis("MC_MoveAbsolute", McMoveAbsolute::INPUTS, |_| {
        Box::<McMoveAbsolute>::default()
    }),
    BlockSpec::on_axis("MC_MoveRelative", McMoveRelative::INPUTS, |_| {
        Box::<McMoveRelative>::default()
    }),
    BlockSpec::on_axis(
        "MC_MoveVelocity",
        &[
            VELOCITY,
            input("direction", Kind::OneOf(&[("1", 1), ("-1", -1)])),
            ACCELERATION,
            DECELERATION,
            JERK,
        ],
        |_| {
            Box::new(McMoveVelocity {
                direction: 1,
                ..McMoveVelocity::default()
            })
        },
    ),
    BlockSpec::on_axis("MC_MoveSuperimposed", McMoveSuperimposed::INPUTS, |_| {
        Box::<McMoveSuperimposed>::default()
    }),
    BlockSpec::on_axis("MC_Halt", McHalt::INPUTS, |_| Box::<McHalt>::default()),
    BlockSpec::on_axis("MC_Stop", &[DECELERATION, JERK], |_| {
        Box::<McStop>::default()
    }),
    BlockSpec::on_axis("MC_SetPosition", McSetPosition::INPUTS, |_| {
        Box::<McSetPosition>::default()
    }),
];
