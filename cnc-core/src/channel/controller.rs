//! The channels of a controller ticking together on one image: masters before the channels
//! that follow them, so a slave sees its master's frame of the same tick. Their axes live in
//! the machine's axis set (`crate::machine`), which hands each channel's set-points on.

use super::dyn_cs::MasterSample;
use super::folder::Loader;
use super::plc_io::{read_inputs, write_outputs, ChannelInputs, Violations};
use super::run::{Channel, MAX_CHANNELS};
use super::sync::SyncBoard;
use hli::views::CncView;

/// All channels.
#[derive(Debug)]
pub struct Controller {
    channels: Vec<Channel>,
    masters: [Option<MasterSample>; MAX_CHANNELS],
    inputs: [ChannelInputs; MAX_CHANNELS],
    /// What the channels refused of the PLC's writes, summed over the run.
    violations: Violations,
    sync: SyncBoard,
    order: [usize; MAX_CHANNELS],
}

/// A set of channels the controller cannot hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ControllerError {
    /// More channels than the image has.
    #[error("at most {MAX_CHANNELS} channels, found {0}")]
    TooManyChannels(usize),
}

impl Controller {
    /// The channels, index = position.
    pub fn new(mut channels: Vec<Channel>) -> Result<Self, ControllerError> {
        if channels.len() > MAX_CHANNELS {
            return Err(ControllerError::TooManyChannels(channels.len()));
        }
        let n = channels.len();
        for channel in &mut channels {
            channel.set_channel_count(n);
        }
        Ok(Self {
            channels,
            masters: [None; MAX_CHANNELS],
            inputs: [ChannelInputs::default(); MAX_CHANNELS],
            violations: Violations::default(),
            sync: SyncBoard::default(),
            order: core::array::from_fn(|i| i),
        })
    }

    /// The channels.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// One channel, mutable (to start programs).
    pub fn channel_mut(&mut self, index: usize) -> Option<&mut Channel> {
        self.channels.get_mut(index)
    }

    /// One tick of every channel with its PLC units: [`Controller::read_plc`],
    /// [`Controller::tick_channels`], [`Controller::write_plc`] (a machine runs the three as
    /// stages of its own tick, with its axes and engines between).
    pub fn tick(&mut self, view: &CncView<'_>) {
        self.read_plc(view);
        self.tick_channels();
        self.write_plc(view);
    }

    /// Reads what the PLC gave each channel.
    pub fn read_plc(&mut self, view: &CncView<'_>) {
        for (i, channel) in self.channels.iter().enumerate() {
            read_inputs(view, channel.index(), channel.wanted(), &mut self.inputs[i]);
            self.violations.add(&self.inputs[i].violations);
        }
    }

    /// Between ticks: the channels' program loading and starting their control units asked
    /// for, and the text of a new error for the state block (allocates; never in a tick).
    /// With a `loader`, programs are loaded on its thread and taken over here when ready
    /// (the real-time loop); without one, here and now (lockstep and in-process runs stay
    /// deterministic). Returns how many channels were served.
    pub fn serve_channels(&mut self, loader: Option<&Loader>) -> usize {
        let mut served = 0;
        while let Some(loaded) = loader.and_then(Loader::try_take) {
            if let Some(channel) = self.channels.get_mut(loaded.channel) {
                channel.finish_select(loaded);
                served += 1;
            }
        }
        for channel in &mut self.channels {
            if channel.wants_service() {
                channel.serve(loader);
                served += 1;
            }
        }
        served
    }

    /// What the channels refused of the PLC's writes so far, by class.
    pub fn violations(&self) -> &Violations {
        &self.violations
    }

    /// One tick of every channel on the inputs read last: channels that follow no other
    /// channel first, then the followers in index order.
    pub fn tick_channels(&mut self) {
        let n = self.channels.len();
        let mut k = 0;
        for pass in 0..2 {
            for i in 0..n {
                let follows = self.channels[i].follows_channel().is_some();
                if follows == (pass == 1) {
                    self.order[k] = i;
                    k += 1;
                }
            }
        }
        let running = self
            .channels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.may_signal())
            .fold(0u32, |mask, (i, _)| mask | 1 << i);
        self.sync.set_running(running);
        for k in 0..n {
            let i = self.order[k];
            self.channels[i].tick(&self.inputs[i], &self.masters, &mut self.sync);
            self.masters[i] = self.channels[i].published();
            if self.channels[i].take_aborted() {
                self.sync.note_abort();
            }
        }
    }

    /// Writes what each channel shows the PLC.
    pub fn write_plc(&mut self, view: &CncView<'_>) {
        for channel in &mut self.channels {
            let index = channel.index();
            write_outputs(view, index, channel.outputs_mut());
        }
    }
}
