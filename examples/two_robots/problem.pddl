; Two robots, two parts: the floor robot kits the red battery onto agv1 while
; the ceiling robot brings the blue pump to assembly station as1.
(define (problem two_robots)
  (:domain ariac_domain)
  (:objects floor_robot ceiling_robot - robot
            battery_red pump_blue - part
            floor_home ceiling_home bin1 bin2 agv1 as1 - container)
  (:init (is_enabled floor_robot) (is_enabled ceiling_robot)
         (is_reachable floor_robot floor_home)
         (is_reachable ceiling_robot ceiling_home)
         (on battery_red bin1) (on pump_blue bin2))
  (:goal (and (on battery_red agv1) (on pump_blue as1))))
