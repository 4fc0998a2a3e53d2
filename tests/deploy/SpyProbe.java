// Runs LCM's own lcm-spy (lcm.spy.Spy) unchanged in this JVM and, twice a
// second, prints what its windows show: the title of every window and every
// row of the channel table, with the screen position of the row, so a test
// can tell whether lcm-spy decoded our types and where to double-click.
//
//   window<TAB>title
//   row<TAB>channel<TAB>type<TAB>messages<TAB>undecodable<TAB>x<TAB>y
//   viewer<TAB>title<TAB>object panels
//   end
import java.awt.Component;
import java.awt.Container;
import java.awt.Frame;
import java.awt.Point;
import java.awt.Rectangle;
import java.awt.Window;
import javax.swing.JTable;
import javax.swing.SwingUtilities;

public class SpyProbe {
  public static void main(String[] args) throws Exception {
    lcm.spy.Spy.main(args);
    while (true) {
      Thread.sleep(500);
      SwingUtilities.invokeAndWait(SpyProbe::dump);
    }
  }

  private static void dump() {
    StringBuilder out = new StringBuilder();
    for (Window w : Window.getWindows()) {
      if (!w.isShowing()) continue;
      String title = w instanceof Frame ? ((Frame) w).getTitle() : "";
      out.append("window\t").append(title).append('\n');
      int panels = count(w, "lcm.spy.ObjectPanel");
      if (panels > 0) out.append("viewer\t").append(title).append('\t').append(panels).append('\n');
      tables(w, out);
    }
    out.append("end\n");
    System.out.print(out);
    System.out.flush();
  }

  private static int count(Component c, String className) {
    int n = c.getClass().getName().equals(className) ? 1 : 0;
    if (c instanceof Container) {
      for (Component child : ((Container) c).getComponents()) n += count(child, className);
    }
    return n;
  }

  private static void tables(Component c, StringBuilder out) {
    if (c instanceof JTable) {
      JTable t = (JTable) c;
      int undecodable = t.getColumnCount() - 1;
      for (int col = 0; col < t.getColumnCount(); ++col) {
        if (t.getColumnName(col).startsWith("Undecodable")) undecodable = col;
      }
      for (int row = 0; row < t.getRowCount(); ++row) {
        Rectangle r = t.getCellRect(row, 0, true);
        Point p = new Point(r.x + r.width / 2, r.y + r.height / 2);
        if (t.isShowing()) SwingUtilities.convertPointToScreen(p, t);
        out.append("row\t").append(t.getValueAt(row, 0)).append('\t').append(t.getValueAt(row, 1))
           .append('\t').append(t.getValueAt(row, 2)).append('\t').append(t.getValueAt(row, undecodable))
           .append('\t').append(p.x).append('\t').append(p.y).append('\n');
      }
    }
    if (c instanceof Container) {
      for (Component child : ((Container) c).getComponents()) tables(child, out);
    }
  }
}
