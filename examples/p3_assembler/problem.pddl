(define (problem p3_three_operations)
  (:domain p3_assembler)
  (:objects robot1 - agent
            home tool_rack - location
            screwdriver wrench drill - tool)
  (:init (at robot1 home) (hand_free robot1)
         (tool_at screwdriver tool_rack) (tool_at wrench tool_rack)
         (tool_at drill tool_rack))
  (:goal (and (op1_done) (op2_done) (op3_done) (at robot1 home))))
