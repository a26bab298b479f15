! RAPID flow: IF/ELSEIF, WHILE, FOR with STEP, TEST, FUNC, DIV/MOD/XOR, Round.
module Flow
  var num total := 0;
  pers num mode := 2;

  func num Twice(num x)
    return 2 * x;
  endfunc

  proc main()
    var num n := 7;
    var bool odd;
    odd := n MOD 2 = 1;
    if odd AND NOT n > 10 then
      total := Twice(n DIV 2);
    elseif n = 0 then
      total := -1;
    else
      Decr total;
    endif
    while n > 0 do
      Add total, n;
      n := n - 3;
    endwhile
    for k from 10 to 0 step -5 do
      Incr total;
    endfor
    test mode
      case 1, 2:
        total := Round(total / 4);
      case 3:
        total := Trunc(Sin(30) * 10 + ATan2(1, 1));
      default:
        Stop;
    endtest
    if (odd XOR TRUE) total := 0;
    TPWrite "total " + NumToStr(total, 0);
  endproc
endmodule
