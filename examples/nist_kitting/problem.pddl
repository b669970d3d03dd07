(define (problem kit-two-parts)
  (:domain kitting)
  (:objects robot1 - robot
            gripper_small - endeffector
            holder1 - holder
            part_a1 part_b1 - part
            tray_a tray_b - partstray
            kit1 - kit)
  (:init (robot-empty robot1) (eff-in-holder gripper_small holder1)
         (eff-fits gripper_small part_a1) (eff-fits gripper_small part_b1)
         (part-in-tray part_a1 tray_a) (part-in-tray part_b1 tray_b))
  (:goal (and (part-in-kit part_a1 kit1) (part-in-kit part_b1 kit1)
              (eff-in-holder gripper_small holder1))))
