//! The channels of a controller ticking together on one image: masters before the channels
//! that follow them, so a slave sees its master's frame of the same tick. Each channel's axes
//! take the next free axis images (`gpAx[k]^`), in channel order.

use super::axes_out::AxisPublisher;
use super::dyn_cs::MasterSample;
use super::run::{Channel, MAX_CHANNELS};
use super::sync::SyncBoard;
use hli::layout::HLI_MAX_AXES;
use hli::views::CncView;

/// All channels.
#[derive(Debug)]
pub struct Controller {
    channels: Vec<Channel>,
    axes: Vec<Option<AxisPublisher>>,
    axis_images: usize,
    masters: [Option<MasterSample>; MAX_CHANNELS],
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
    pub fn new(channels: Vec<Channel>, cycle_s: f64) -> Result<Self, ControllerError> {
        if channels.len() > MAX_CHANNELS {
            return Err(ControllerError::TooManyChannels(channels.len()));
        }
        let mut axes = Vec::with_capacity(channels.len());
        let mut first = 0;
        for c in &channels {
            let n = c.config().axes.len();
            let fits = first + n <= HLI_MAX_AXES;
            axes.push(fits.then(|| AxisPublisher::new(first, c.set_points(), cycle_s)));
            if fits {
                first += n;
            }
        }
        Ok(Self {
            channels,
            axes,
            axis_images: first,
            masters: [None; MAX_CHANNELS],
            sync: SyncBoard::default(),
            order: core::array::from_fn(|i| i),
        })
    }

    /// The channels.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Axis images the channels use together.
    pub fn axis_images(&self) -> usize {
        self.axis_images
    }

    /// Index of the first axis image of channel `index` (None: no room left in the image).
    pub fn first_axis(&self, index: usize) -> Option<usize> {
        self.axes.get(index)?.as_ref().map(AxisPublisher::first)
    }

    /// One channel, mutable (to start programs).
    pub fn channel_mut(&mut self, index: usize) -> Option<&mut Channel> {
        self.channels.get_mut(index)
    }

    /// One tick of every channel.
    pub fn tick(&mut self, view: &CncView<'_>) {
        let n = self.channels.len();
        // Channels that follow no other channel first, then the followers in index order.
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
        for k in 0..n {
            let i = self.order[k];
            self.channels[i].tick(view, &self.masters, &mut self.sync);
            self.masters[i] = self.channels[i].published();
            if let Some(axes) = self.axes[i].as_mut() {
                axes.publish(view, self.channels[i].set_points());
            }
        }
    }
}
