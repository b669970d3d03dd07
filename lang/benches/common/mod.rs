//! Inputs shared by the benchmarks.

/// A valid ARIAC plan of exactly `steps` steps: the robot carries the red
/// battery between bin1 and agv1, ending with it on agv1 when
/// `steps % 6 == 4` (as for 100,000).
pub fn long_ariac_plan(steps: usize) -> String {
    let mut s = String::from("(move floor_robot curr_position bin1)\n");
    let cycle = [
        "(grasp floor_robot battery_red bin1)",
        "(move floor_robot bin1 agv1)",
        "(place floor_robot battery_red agv1)",
        "(grasp floor_robot battery_red agv1)",
        "(move floor_robot agv1 bin1)",
        "(place floor_robot battery_red bin1)",
    ];
    for i in 0..steps - 1 {
        s.push_str(cycle[i % 6]);
        s.push('\n');
    }
    s
}
