//! The tool data record (`D..`) on the channel's kinematics: the tool point of the record is
//! the tool pose the channel programs, displays and measures its tracking error on.

use super::Channel;
use kinematics::frame::offset_frame;
use kinematics::{Kinematics, PoseWords};
use nalgebra::Isometry3;

impl Channel {
    /// `D..` selected record `d` (0: none): its length along the flange's tool axis and its
    /// orientation go on the kinematics. Under a transformation the axes stay where they are
    /// and the programmed pose becomes the new tool point's (as at `#TRAFO ON`): the next
    /// motion block moves the new tool point.
    pub(super) fn select_tool_record(&mut self, d: u32) {
        let frame = self
            .config
            .nc
            .tools
            .iter()
            .find(|t| t.d == d)
            .and_then(|t| {
                let words = PoseWords {
                    xyz: [0.0, 0.0, t.length],
                    abc: t.orientation,
                };
                offset_frame(&words, false).ok()
            })
            .unwrap_or_else(Isometry3::identity);
        self.pose.kinematics.set_tool(frame);
        self.pose.tool = self
            .pose
            .kinematics
            .forward(&self.pose.joints)
            .unwrap_or(self.pose.tool);
        if self.pose.trafo {
            self.program_tool_pose();
        }
    }
}
